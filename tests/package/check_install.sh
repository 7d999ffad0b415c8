#!/bin/bash
# The installed package works for a user's program (CTest package.example): install the build
# into a fresh prefix, build examples/minimal against it with find_package(pkslam), and run the
# example on a 3 s simulated stereo sequence.
#   tests/package/check_install.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
src=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/pkslam_package.XXXXXX")
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
test -f "$work/prefix/include/pkslam/pkslam.h"
test -f "$work/prefix/lib/cmake/pkslam/pkslamConfig.cmake"
cmake -S "$src/examples/minimal" -B "$work/example" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_BUILD_TYPE=Release > "$work/configure.log"
cmake --build "$work/example" -j2 > "$work/build.log"
"$work/prefix/bin/pkslam" --log-level warn simulate --out "$work/seq" --motion medium --duration 3 \
  --quality fast --quiet --no-cloud --seed 1
"$work/example/stereo_euroc" "$work/seq" "$work/seq/settings.yaml" "$work/trajectory.txt"
test -s "$work/trajectory.txt"
echo "package ok: installed into a fresh prefix, example built and run"
