#!/usr/bin/env bash
# build_v10_counter.sh OUT
#
# The ORB-SLAM3 v1.0 peer (../shared/tools/peer, built in $PEER, default /tmp/peer) with one line
# added to its two inertial EuRoC examples: after SLAM.Shutdown() they write KeyFrame::nNextId
# (keyframes created, culled ones too) to ./keyframes_created.txt, as the v0.3 peers do
# (build_pks_peers.sh, patch d). Nothing else changes: the examples are compiled with the flags
# of $PEER's own CMake build and linked against its libORB_SLAM3.so, so the system is the one
# the bench's `orbslam3-peer` runs. OUT becomes a peer folder for scripts/run_peer:
#
#   evaluation/studies/pks/peers/build_v10_counter.sh /tmp/peer-count
#   PEER=/tmp/peer-count NICE=0 scripts/run_peer SEQ stereo-inertial RUN   # RUN/keyframes_created.txt
#
# Why: the study compares the rate at which pkslam's `orbslam3` reading creates keyframes with
# the binary of the rule it reads (docs/pks_study.md, round 2); the v1.0 peer as built does not
# report it. About a minute per example on a quiet machine.
set -euo pipefail
[ $# -eq 1 ] || { echo "usage: $0 OUT" >&2; exit 2; }
peer=${PEER:-/tmp/peer}
out=$1
orb=$peer/src/ORB_SLAM3
build=$orb/build
[ -f "$orb/lib/libORB_SLAM3.so" ] || { echo "build_v10_counter.sh: $orb/lib/libORB_SLAM3.so missing: build the peer first (../shared/tools/peer/README.md)" >&2; exit 2; }
mkdir -p "$out/bin" "$out/examples"
ln -sfn "$peer/src" "$out/src"
ln -sfn "$peer/install" "$out/install"
ln -sfn "$peer/ORBvoc.txt" "$out/ORBvoc.txt"

for pair in Stereo-Inertial/stereo_inertial_euroc Monocular-Inertial/mono_inertial_euroc; do
  name=${pair#*/}
  flags=$build/CMakeFiles/$name.dir/flags.make
  link=$build/CMakeFiles/$name.dir/link.txt
  [ -f "$flags" ] && [ -f "$link" ] || { echo "build_v10_counter.sh: $flags or $link missing (the peer's CMake build tree)" >&2; exit 2; }
  src=$out/examples/$name.cc
  cp "$orb/Examples/$pair.cc" "$src"
  grep -q 'keyframes_created.txt' "$src" ||
    sed -i 's/^\([[:space:]]*\)SLAM\.Shutdown();[[:space:]]*$/&\n\1{ std::ofstream kf_count("keyframes_created.txt"); kf_count << ORB_SLAM3::KeyFrame::nNextId << std::endl; } \/\/ [v10-counter]/' "$src"
  grep -q 'v10-counter' "$src" || { echo "build_v10_counter.sh: no 'SLAM.Shutdown();' line in $orb/Examples/$pair.cc" >&2; exit 1; }
  # The CMake build's own compile and link lines, with this source and output.
  defines=$(sed -n 's/^CXX_DEFINES = //p' "$flags")
  includes=$(sed -n 's/^CXX_INCLUDES = //p' "$flags")
  cxxflags=$(sed -n 's/^CXX_FLAGS = //p' "$flags")
  libs=$(sed 's/^.* -o [^ ]* //' "$link")
  echo "[v10-counter] $name"
  eval "/usr/bin/c++ $cxxflags $defines $includes -w -rdynamic \"$src\" -o \"$out/bin/$name\" $libs"
done
echo "ORB-SLAM3 v1.0 peer of $peer, inertial examples + keyframe counter (build_v10_counter.sh)" > "$out/build_id.txt"
echo "[v10-counter] done: PEER=$out scripts/run_peer SEQ SENSOR RUN"
