#!/bin/bash
# The installed package works for a user's program (CTest package.example): install the build
# into a fresh prefix, build examples/minimal against it with find_package(pkslam), and run the
# example on a 3 s simulated stereo sequence; then the installed Python package on it.
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
# The Python package from the same prefix: its paths point into the prefix, and it tracks.
PYTHONPATH="$work/prefix/lib/python3/dist-packages" /usr/bin/python3 - "$work" <<'PY'
import glob, os, sys
import cv2
import pkslam
work = sys.argv[1]
assert pkslam._executable().startswith(work), pkslam._executable()
assert pkslam.VOCABULARY.startswith(work) and os.path.exists(pkslam.VOCABULARY), pkslam.VOCABULARY
seq = os.path.join(work, "seq")
slam = pkslam.Slam(os.path.join(seq, "settings.yaml"), pkslam.VOCABULARY, sensor="stereo")
for left in sorted(glob.glob(os.path.join(seq, "mav0/cam0/data/*.png")))[:30]:
    right = left.replace("/cam0/", "/cam1/")
    slam.track_stereo(cv2.imread(left, 0), cv2.imread(right, 0), int(os.path.basename(left)[:-4]))
slam.shutdown()
assert slam.num_keyframes >= 1 and len(slam.map_points()[1]) > 50, slam.num_keyframes
PY
echo "package ok: installed into a fresh prefix, example built and run, Python package imported and run"
