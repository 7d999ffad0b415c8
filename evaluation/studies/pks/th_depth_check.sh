#!/usr/bin/env bash
# th_depth_check.sh RENDERING OUT
#
# How much of the gap between the keyframe rate of pkslam's `orbslam3-v03` reading and the v0.3
# binary it reads (docs/pks_study.md, round 2) is the close-point depth, ThDepth: the authors'
# v0.3 settings file (the peers' template) has 35 baselines, ORB-SLAM3 v1.0's EuRoC files (and
# pkslam's default) 60. On one stereo-inertial rendering (a study's sim_cache entry or any
# `pkslam simulate` output), one run each:
#   pkslam orbslam3-v03     $PKSLAM run (live emulation on the work clock: load does not move it)
#   v0.3 binary             $PKS_PEER/base (run_pks_peer with V03_THDEPTH)
#   v1.0 binary             $PEER_COUNT (build_v10_counter.sh: the v1.0 peer that counts), at
#                           60 only (the study's v1.0 peer; its rule is v0.3's without the exit)
# and prints keyframes created (culled ones too) and kept. The two binaries pace themselves to
# real time (v0.3) or run unpaced (v1.0): run this on an otherwise quiet machine, as the study.
#
#   PKS_PEER=/tmp/pks-peer PEER_COUNT=/tmp/peer-count NICE=0 \
#       evaluation/studies/pks/th_depth_check.sh SIM_CACHE/real_MH_02_easy-seed200-... OUT
set -euo pipefail
[ $# -eq 2 ] || { echo "usage: $0 RENDERING OUT" >&2; exit 2; }
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
seq=$(cd "$1" && pwd)
out=$2
pkslam=${PKSLAM:-$root/build/bin/pkslam}
pks_peer=${PKS_PEER:-/tmp/pks-peer}
peer_count=${PEER_COUNT:-}
tools=${PKSLAM_PEER_TOOLS:-$root/../shared/tools/peer}
export NICE=${NICE:-0}
[ -f "$seq/mav0/cam0/sensor.yaml" ] || { echo "th_depth_check.sh: $seq is not a EuRoC folder" >&2; exit 2; }
mkdir -p "$out"
out=$(cd "$out" && pwd)

for depth in 60 35; do
  run=$out/pkslam_th$depth
  if [ ! -f "$run/stats.json" ]; then
    args=()
    if [ "$depth" != 60 ]; then
      sed "s/^Stereo.ThDepth:.*/Stereo.ThDepth: $depth.0/" \
          "$out/pkslam_th60/calibration/settings.yaml" > "$out/pkslam_th$depth.yaml"
      args=(--settings "$out/pkslam_th$depth.yaml")
    fi
    echo "[th-depth] pkslam orbslam3-v03, ThDepth $depth"
    "$pkslam" run --dataset "$seq" --out "$run" --sensor stereo-inertial --selector orbslam3 \
        --param no_keyframe_while_imu_initialises=1 --seed 1 --quiet "${args[@]}" > "$run.log" 2>&1
  fi
done

if [ -d "$pks_peer/base" ]; then
  for depth in 35 60; do
    run=$out/v03_th$depth
    [ -f "$run/keyframes_created.txt" ] && continue
    echo "[th-depth] v0.3 binary, ThDepth $depth"
    V03_THDEPTH="$depth.0" PKS_PEER="$pks_peer" PKSLAM_PEER_TOOLS="$tools" \
        "$here/peers/run_pks_peer" base "$seq" stereo-inertial "$run" > "$run.log" 2>&1 ||
      echo "[th-depth] v0.3 binary failed: $run.log"
  done
else
  echo "[th-depth] no v0.3 peer in $pks_peer (build_pks_peers.sh): skipped"
fi

if [ -n "$peer_count" ]; then
  run=$out/v10_th60
  if [ ! -f "$run/keyframes_created.txt" ]; then
    echo "[th-depth] v1.0 binary, ThDepth 60 (its EuRoC file's)"
    PEER="$peer_count" "$root/scripts/run_peer" "$seq" stereo-inertial "$run" > "$run.log" 2>&1 ||
      echo "[th-depth] v1.0 binary failed: $run.log"
  fi
else
  echo "[th-depth] PEER_COUNT not set (build_v10_counter.sh): the v1.0 binary skipped"
fi

/usr/bin/python3 - "$out" <<'PY'
import json, os, sys
out = sys.argv[1]
print('| system | ThDepth | keyframes created | in the final map |')
print('|---|---|---|---|')
for name, label in (('pkslam', 'pkslam orbslam3-v03'), ('v03', 'ORB-SLAM3 v0.3 binary'),
                    ('v10', 'ORB-SLAM3 v1.0 binary')):
    for depth in (35, 60):
        run = os.path.join(out, '%s_th%d' % (name, depth))
        created = kept = None
        if os.path.isfile(os.path.join(run, 'stats.json')):
            stats = json.load(open(os.path.join(run, 'stats.json')))
            created, kept = stats.get('keyframes_created'), stats.get('keyframes')
        elif os.path.isfile(os.path.join(run, 'keyframes_created.txt')):
            created = int(open(os.path.join(run, 'keyframes_created.txt')).read().split()[0])
            kf = os.path.join(run, 'kf_peer.txt')  # the final map's keyframes, one per line
            if os.path.isfile(kf):
                kept = sum(1 for line in open(kf) if line.strip() and not line.startswith('#'))
        if created is not None:
            print('| %s | %d | %s | %s |' % (label, depth, created, kept if kept is not None else 'n/a'))
PY
