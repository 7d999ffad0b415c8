#!/usr/bin/env bash
# build_pks_peers.sh -- builds the two measuring instruments of the PKS study (issue 39):
#   pks   the PKS authors' released code (github arashazimi0032/PKS): a whole ORB-SLAM3 v0.3 tree
#         in which the authors changed src/Tracking.cc, src/LocalMapping.cc and their headers;
#   base  ORB-SLAM3 v0.3 unmodified, the revision those four files derive from: the same tree
#         with the four files taken from ORB-SLAM3 v0.3 (UZ-SLAMLab/ORB_SLAM3, tag v0.3).
# Both are GPLv3 programs run beside pkslam, never part of it (README.md beside this script).
#
# Usage:  PKS_GIT=DIR PANGO_GIT=DIR V03_FILES=DIR bash build_pks_peers.sh
#   PKS_GIT    git directory of github.com/arashazimi0032/PKS (bare is fine)
#   PANGO_GIT  git directory of github.com/stevenlovegrove/Pangolin (tag v0.9.1 is built), or
#   PANGO_PREFIX  an installed Pangolin (e.g. the ORB-SLAM3 peer's /tmp/peer/install)
#   V03_GIT    a git directory holding UZ-SLAMLab/ORB_SLAM3's history (V03_REF, default its one
#              V0.3 commit ef97841, "Updated to V0.3beta", 2020-09-07; the fork
#              sumborwonpob/ORB_SLAM3 keeps that history, 18 MB), or V03_FILES, a folder with
#              v0.3's src/Tracking.cc, src/LocalMapping.cc, include/Tracking.h,
#              include/LocalMapping.h. Without either only `pks` is built.
# Env:    PKS_PEER=/tmp/pks-peer  JOBS=2  PKS_REF=a6a7dc5 (PKS master, 2021-07-25)
#
# Result: $PKS_PEER/{pks,base}/bin/{stereo_inertial_euroc,mono_inertial_euroc}, each variant laid
# out as the ORB-SLAM3 peer's $PEER (bin/, src/ORB_SLAM3/Examples, install/lib, ORBvoc.txt), so
# ../shared/tools/peer/run_orbslam3.sh runs either (run_pks_peer beside this script does).
#
# Patches (each idempotent, marked "[pks-peer]" in the sources; the same for both variants):
#  P1 CMakeLists.txt (top, DBoW2, g2o): find_package(OpenCV 3 / 3.0) -> 4 (Debian 12 has 4.6),
#     -std=c++11 -> -std=c++17 (Pangolin 0.9 headers need C++17; COMPILEDWITHC11 stays defined),
#     -march=native dropped everywhere (one instruction set for g2o, DBoW2 and the library, so
#     Eigen's alignment agrees between them, and binaries that run on any machine of a study),
#     `add_subdirectory(Thirdparty/g2o)` dropped (g2o is built first, as upstream's build.sh
#     does; the library links it by path), and only the library and the two inertial EuRoC
#     examples are built.
#  P2 Examples (stereo_inertial_euroc, mono_inertial_euroc):
#     a) System(..., bUseViewer=true) -> false (no window, no X display);
#     b) after `vTimesTrack[ni]=ttrack;` one line "t_frame_s t_track_s" per frame is appended to
#        ./track_times.txt (run_orbslam3.sh reads it);
#     c) bound check `first_imu[seq]<nImu[seq] &&` in the per-frame IMU loop (the examples read
#        past the IMU log when it ends at the last image, as in pkslam's renders);
#     d) after Shutdown(), KeyFrame::nNextId (keyframes created, culled ones too) is written to
#        ./keyframes_created.txt (the bench's keyframes_created).
#     The real-time pacing (usleep to the next frame's time) is KEPT: the released selector reads
#     local mapping's state ("no keyframe while the IMU initialises", the idle test), so an
#     unpaced run would not be the run the authors made (issue 39, item 5).
#  P3 src/LoopClosing.cc: `mnFullBAIdx++;` on a bool (ill-formed in C++17) -> `= true` (same).
#  P4 build fixes for OpenCV 4 / gcc 12, none changing behaviour (p4_fixes below): opencv/cv.h
#     -> opencv2/opencv.hpp + imgproc/types_c.h; CV_LOAD_IMAGE_UNCHANGED -> cv::IMREAD_UNCHANGED;
#     KeyFrameAndPose's allocator pair<const KeyFrame*, Sim3> -> pair<KeyFrame* const, Sim3>.
#  P5 The authors' Tracking::NeedNewKeyFrame writes ./diff.txt (every keyframe, every frame) and
#     ./diff2.txt: left as released (they are the authors' code; the run's folder holds them).
set -euo pipefail

HERE=$(cd "$(dirname "$0")" && pwd)
PKS_PEER=${PKS_PEER:-/tmp/pks-peer}
JOBS=${JOBS:-2}
NICE=(nice -n 19)
PKS_GIT=${PKS_GIT:?set PKS_GIT to a git directory of github.com/arashazimi0032/PKS}
PKS_REF=${PKS_REF:-a6a7dc5}
PANGO_REF=${PANGO_REF:-v0.9.1}
V03_REF=${V03_REF:-ef9784101fbd28506b52f233315541ef8ba7af57}
SELECTION_FILES=(src/Tracking.cc src/LocalMapping.cc include/Tracking.h include/LocalMapping.h)
EXAMPLES=(stereo_inertial_euroc mono_inertial_euroc)

mkdir -p "$PKS_PEER"
# The two trees differ in four files: with paths taken relative to $PKS_PEER, ccache compiles
# everything else once.
export CCACHE_BASEDIR=$PKS_PEER
TIMES=$PKS_PEER/build_time.txt
: > "$TIMES"
stage() { # stage NAME CMD...
  local name=$1; shift
  local t0=$SECONDS
  echo "=== [$name] $(date +%T)"
  "$@"
  echo "$name $((SECONDS - t0)) s" | tee -a "$TIMES"
}
die() { echo "build_pks_peers.sh: $*" >&2; exit 2; }

# ---------------------------------------------------------------- Pangolin
pangolin() {
  if [ -n "${PANGO_PREFIX:-}" ]; then
    [ -d "$PANGO_PREFIX/lib/cmake/Pangolin" ] || die "no Pangolin in $PANGO_PREFIX/lib/cmake/Pangolin"
    PANGO_INSTALL=$PANGO_PREFIX
    return
  fi
  PANGO_INSTALL=$PKS_PEER/install
  [ -f "$PANGO_INSTALL/lib/cmake/Pangolin/PangolinConfig.cmake" ] && { echo "Pangolin already installed"; return; }
  local git=${PANGO_GIT:?set PANGO_GIT (or PANGO_PREFIX)} src=$PKS_PEER/src/Pangolin
  rm -rf "$src"; mkdir -p "$src"
  git --git-dir="$git" archive "$PANGO_REF" | tar -x -C "$src"
  cmake -S "$src" -B "$PKS_PEER/build/pangolin" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_INSTALL_PREFIX="$PANGO_INSTALL" -DBUILD_EXAMPLES=OFF -DBUILD_TOOLS=OFF -DBUILD_TESTS=OFF \
    -DBUILD_PANGOLIN_PYTHON=OFF -DBUILD_PANGOLIN_FFMPEG=OFF -DBUILD_PANGOLIN_LIBRAW=OFF \
    -DBUILD_PANGOLIN_LIBOPENEXR=OFF -DBUILD_PANGOLIN_LIBDC1394=OFF -DBUILD_PANGOLIN_V4L=OFF \
    -DBUILD_PANGOLIN_REALSENSE=OFF -DBUILD_PANGOLIN_REALSENSE2=OFF -DBUILD_PANGOLIN_OPENNI=OFF \
    -DBUILD_PANGOLIN_OPENNI2=OFF -DBUILD_PANGOLIN_LIBUVC=OFF -DBUILD_PANGOLIN_DEPTHSENSE=OFF \
    -DBUILD_PANGOLIN_TELICAM=OFF -DBUILD_PANGOLIN_PLEORA=OFF
  "${NICE[@]}" cmake --build "$PKS_PEER/build/pangolin" -j"$JOBS"
  cmake --install "$PKS_PEER/build/pangolin" > /dev/null
}

# ---------------------------------------------------------------- sources
# The tree the authors released, minus the files no build needs (images, example IMU logs).
export_pks() { # export_pks DEST
  local dest=$1
  if [ -f "$dest/.pks_ref" ] && [ "$(cat "$dest/.pks_ref")" = "$PKS_REF" ]; then
    echo "$dest already exported at $PKS_REF"; return
  fi
  rm -rf "$dest"; mkdir -p "$dest"
  # Snapshots of the repository may lack its large blobs (the examples' IMU logs, the
  # vocabulary), none of which a build needs: export the files whose blobs exist.
  local list; list=$(mktemp)
  git --git-dir="$PKS_GIT" ls-tree -r "$PKS_REF" -- CMakeLists.txt include src Thirdparty Examples \
    | awk -F'\t' '{split($1, a, " "); print a[3] "\t" $2}' \
    | while IFS=$'\t' read -r blob path; do
        git --git-dir="$PKS_GIT" cat-file -e "$blob" 2>/dev/null && printf '%s\n' "$path"
      done > "$list"
  xargs -d '\n' git --git-dir="$PKS_GIT" archive "$PKS_REF" -- < "$list" | tar -x -C "$dest"
  echo "exported $(wc -l < "$list") files of $PKS_REF into $dest"
  rm -f "$list"
  echo "$PKS_REF" > "$dest/.pks_ref"
}
# The baseline: the same tree with ORB-SLAM3 v0.3's own four files.
v03_file() { # v03_file RELPATH -> its v0.3 text on stdout
  if [ -n "${V03_FILES:-}" ]; then
    cat "$V03_FILES/$1"
  else
    git --git-dir="${V03_GIT:?set V03_FILES or V03_GIT}" show "$V03_REF:$1"
  fi
}
export_base() {
  local dest=$PKS_PEER/base/src/ORB_SLAM3
  export_pks "$dest"
  local f
  for f in "${SELECTION_FILES[@]}"; do
    v03_file "$f" > "$dest/$f.v03" || die "cannot read v0.3's $f"
    if cmp -s "$dest/$f.v03" "$dest/$f"; then rm "$dest/$f.v03"; else mv "$dest/$f.v03" "$dest/$f"; fi
  done
  # The authors changed these four files of v0.3 and no other source: check it on the two
  # revisions (blob ids are content hashes, comparable across repositories).
  if [ -n "${V03_GIT:-}" ]; then
    local changed
    changed=$(join -t $'\t' -a1 -a2 -e none -o 0,1.2,2.2 \
        <(git --git-dir="$PKS_GIT" ls-tree -r "$PKS_REF" -- src include | awk -F'\t' '{split($1,a," "); print $2 "\t" a[3]}' | sort) \
        <(git --git-dir="$V03_GIT" ls-tree -r "$V03_REF" -- src include | awk -F'\t' '{split($1,a," "); print $2 "\t" a[3]}' | sort) \
      | awk -F'\t' '$2 != $3 {print $1}' | sort | tr '\n' ' ')
    echo "sources that differ between the authors' tree and v0.3: $changed"
    [ "$changed" = "$(printf '%s\n' "${SELECTION_FILES[@]}" | sort | tr '\n' ' ')" ] \
      || die "expected the authors' tree to differ from v0.3 in exactly ${SELECTION_FILES[*]}"
  fi
}
have_base() { [ -n "${V03_FILES:-}" ] || [ -n "${V03_GIT:-}" ]; }
sources() {
  export_pks "$PKS_PEER/pks/src/ORB_SLAM3"
  if have_base; then export_base; else echo "no V03_FILES / V03_GIT: the baseline is not built"; fi
}

# ---------------------------------------------------------------- patches (idempotent)
sedif() { if grep -q -- "$2" "$1"; then sed -i "$3" "$1"; fi; }
patch_tree() { # patch_tree ORB_SLAM3_DIR
  local O=$1
  # P1
  local c
  for c in "$O/CMakeLists.txt" "$O/Thirdparty/DBoW2/CMakeLists.txt" "$O/Thirdparty/g2o/CMakeLists.txt"; do
    sedif "$c" 'find_package(OpenCV 3' 's/find_package(OpenCV 3\(\.0\)\?/find_package(OpenCV 4/'
    sedif "$c" ' -march=native' 's/ -march=native//g'
  done
  sedif "$O/CMakeLists.txt" '-std=c++11' 's/-std=c++11/-std=c++17/g'
  sedif "$O/CMakeLists.txt" '^add_subdirectory(Thirdparty/g2o)' 's|^add_subdirectory(Thirdparty/g2o)|# [pks-peer] g2o built first: add_subdirectory(Thirdparty/g2o)|'
  # P3
  sedif "$O/src/LoopClosing.cc" 'mnFullBAIdx++;' 's/^\([[:space:]]*\)mnFullBAIdx++;/\1mnFullBAIdx = true; \/\/ [pks-peer] C++17: was bool++/'
  # P2
  local f
  for f in Monocular-Inertial/mono_inertial_euroc Stereo-Inertial/stereo_inertial_euroc; do
    f=$O/Examples/$f.cc
    grep -q 'viewer off' "$f" || sed -i 's/\(ORB_SLAM3::System SLAM(argv\[1\],argv\[2\],ORB_SLAM3::System::[A-Z_]*, *\)\(true\|false\)\([,)]\)/\1false \/*[pks-peer] viewer off*\/\3/' "$f"
    grep -q 'pks_peer_kf' "$f" || sed -i 's/^\([[:space:]]*\)SLAM\.Shutdown();[[:space:]]*$/&\n\1{ std::ofstream pks_peer_kf("keyframes_created.txt"); pks_peer_kf << ORB_SLAM3::KeyFrame::nNextId << std::endl; } \/\/ [pks-peer]/' "$f"
    grep -q 'pks_peer_tt' "$f" || sed -i 's/^\([[:space:]]*\)vTimesTrack\[ni\]=ttrack;[[:space:]]*$/&\n\1{ static std::ofstream pks_peer_tt("track_times.txt"); pks_peer_tt << std::fixed << std::setprecision(9) << tframe << " " << ttrack << std::endl; } \/\/ [pks-peer]/' "$f"
    sedif "$f" 'while(vTimestampsImu\[seq\]\[first_imu\[seq\]\]<=vTimestampsCam\[seq\]\[ni\])' 's/while(vTimestampsImu\[seq\]\[first_imu\[seq\]\]<=vTimestampsCam\[seq\]\[ni\])/while(first_imu[seq]<nImu[seq] \&\& vTimestampsImu[seq][first_imu[seq]]<=vTimestampsCam[seq][ni]) \/*[pks-peer] bound*\//'
    grep -q '<iomanip>' "$f" || sed -i '0,/#include/s//#include <iomanip> \/\/ [pks-peer]\n#include/' "$f"
    grep -q 'viewer off' "$f" || die "patch P2a failed: $f"
    grep -q 'pks_peer_tt' "$f" || die "patch P2b failed: $f"
    grep -q 'pks-peer\] bound' "$f" || die "patch P2c failed: $f"
    grep -q 'pks_peer_kf' "$f" || die "patch P2d failed: $f"
  done
  # P4: build fixes for gcc 12 / C++17 (behaviour unchanged)
  p4_fixes "$O"
}
p4_fixes() {
  local O=$1
  # OpenCV 4 has no opencv/cv.h; its C constants (CV_BGR2GRAY, ...) live in imgproc/types_c.h.
  sedif "$O/include/ORBextractor.h" '#include <opencv/cv.h>' \
    's|#include <opencv/cv.h>|#include <opencv2/opencv.hpp> // [pks-peer] was opencv/cv.h\n#include <opencv2/imgproc/types_c.h> // [pks-peer]|'
  # OpenCV 4 renamed CV_LOAD_IMAGE_UNCHANGED (same value).
  local f
  for f in src/LoopClosing.cc src/Map.cc src/Optimizer.cc Examples/Monocular-Inertial/mono_inertial_euroc.cc; do
    # (no marker: some of these lines sit inside /* */ blocks)
    sedif "$O/$f" 'CV_LOAD_IMAGE_UNCHANGED' 's/CV_LOAD_IMAGE_UNCHANGED/cv::IMREAD_UNCHANGED/g'
  done
  # libstdc++ 12 checks that a map's allocator holds its value_type, pair<Key const, T>.
  sedif "$O/include/LoopClosing.h" 'std::pair<const KeyFrame\*, g2o::Sim3>' \
    's/std::pair<const KeyFrame\*, g2o::Sim3>/std::pair<KeyFrame* const, g2o::Sim3> \/*[pks-peer]*\//'
}

# ---------------------------------------------------------------- builds
thirdparty() { # DBoW2 and g2o: identical in both trees, built once (in pks/) and linked from base/
  local T=$PKS_PEER/pks/src/ORB_SLAM3/Thirdparty d
  patch_tree "$PKS_PEER/pks/src/ORB_SLAM3"
  for d in DBoW2 g2o; do
    cmake -S "$T/$d" -B "$T/$d/build" -DCMAKE_BUILD_TYPE=Release -Wno-dev
    "${NICE[@]}" cmake --build "$T/$d/build" -j"$JOBS"
  done
  have_base || return 0
  local B=$PKS_PEER/base/src/ORB_SLAM3/Thirdparty
  for d in DBoW2 g2o; do
    rm -rf "$B/$d/lib"; ln -s "$T/$d/lib" "$B/$d/lib"
  done
  cp "$T/g2o/config.h" "$B/g2o/config.h"  # generated by g2o's configure; the headers include it
}
build_variant() { # build_variant pks|base
  local V=$PKS_PEER/$1 O=$PKS_PEER/$1/src/ORB_SLAM3
  patch_tree "$O"
  cmake -S "$O" -B "$O/build" -DCMAKE_BUILD_TYPE=Release -DPangolin_DIR="$PANGO_INSTALL/lib/cmake/Pangolin" \
    -DCMAKE_CXX_COMPILER_LAUNCHER="$(command -v ccache || true)" -Wno-dev
  "${NICE[@]}" cmake --build "$O/build" -j"$JOBS" --target "${EXAMPLES[@]}"
  mkdir -p "$V/bin"
  local e
  for e in "${EXAMPLES[@]}"; do
    ln -sf "$(find "$O/Examples" -maxdepth 2 -type f -name "$e" -perm -u+x | head -1)" "$V/bin/$e"
  done
  ln -sfn "$PANGO_INSTALL" "$V/install"
  # One line naming the build, copied into every run folder (results.csv's peer_build).
  local what="PKS $PKS_REF"
  [ "$1" = base ] && what="ORB-SLAM3 v0.3 $(echo "$V03_REF" | cut -c1-12) (the PKS tree's other files)"
  echo "$1: $what, libORB_SLAM3.so sha256 $(sha256sum "$O/lib/libORB_SLAM3.so" | cut -c1-16)" > "$V/build_id.txt"
  cat "$V/build_id.txt"
  ls -l "$V/bin"
}

T0=$SECONDS
stage pangolin pangolin
stage sources sources
stage thirdparty thirdparty
stage pks build_variant pks
if have_base; then stage base build_variant base; fi
echo "total $((SECONDS - T0)) s" | tee -a "$TIMES"
echo "vocabulary: build/bin/pkslam vocab convert Vocabulary/pkslam_orb_k10_L6.bin $PKS_PEER/pks/ORBvoc.txt (and base/)"
