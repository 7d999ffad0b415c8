#!/usr/bin/env bash
# inertial_search_check.sh RENDERING OUT [SEED...]
#
# Does ORB-SLAM3's inertial front end bring pkslam's reading of ORB-SLAM3's keyframe rule to the
# binaries' keyframe rate, and what does it do to ATE? (docs/pks_study.md, round 2, "the front
# end"). On one stereo-inertial rendering (a study's sim_cache entry or any `pkslam simulate`
# output), `orbslam3` with each of `--inertial-search last-frame` (pkslam's default) and
# `orbslam3`, one run per seed (default: 1); prints keyframes created, lost frames and ATE
# (SE(3), Sim(3), mm) per run. pkslam's offline runs emulate a live run on the work clock, so
# load does not move them and two at a time is fine (JOBS=1 for one at a time).
#
#   evaluation/studies/pks/inertial_search_check.sh SIM_CACHE/real_V1_02_medium-seed400-... OUT 1 2 3
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: $0 RENDERING OUT [SEED...]" >&2; exit 2; }
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
seq=$(cd "$1" && pwd)
out=$2
shift 2
seeds=("$@")
[ ${#seeds[@]} -gt 0 ] || seeds=(1)
pkslam=${PKSLAM:-$root/build/bin/pkslam}
jobs=${JOBS:-2}
gt=$seq/mav0/state_groundtruth_estimate0/data.csv
[ -f "$seq/mav0/cam0/sensor.yaml" ] || { echo "inertial_search_check.sh: $seq is not a EuRoC folder" >&2; exit 2; }
[ -f "$gt" ] || { echo "inertial_search_check.sh: $gt missing (a rendering has its ground truth)" >&2; exit 2; }
mkdir -p "$out"
out=$(cd "$out" && pwd)

# One line per run, "SEARCH SEED", run JOBS at a time.
for seed in "${seeds[@]}"; do
  for search in last-frame orbslam3; do
    echo "$search $seed"
  done
done | xargs -P "$jobs" -L 1 bash -c '
  out=$1 pkslam=$2 seq=$3 search=$4 seed=$5
  run=$out/$search-s$seed
  [ -f "$run/stats.json" ] && exit 0
  echo "[inertial-search] $search, seed $seed"
  "$pkslam" run --dataset "$seq" --out "$run" --sensor stereo-inertial --selector orbslam3 \
      --inertial-search "$search" --seed "$seed" --quiet > "$run.log" 2>&1 ||
    echo "[inertial-search] $search, seed $seed failed: $run.log"' _ "$out" "$pkslam" "$seq"

echo '| front end | seed | keyframes created | lost frames | ATE SE(3) mm | ATE Sim(3) mm |'
echo '|---|---|---|---|---|---|'
for search in last-frame orbslam3; do
  for seed in "${seeds[@]}"; do
    run=$out/$search-s$seed
    [ -f "$run/stats.json" ] || continue
    ate() {
      "$pkslam" eval --gt "$gt" --est "$run/trajectory_body.txt" --align "$1" |
        awk '/^ATE \[m\]/ {printf "%.1f", $3 * 1000}'
    }
    counts=$(/usr/bin/python3 -c 'import json, sys; s = json.load(open(sys.argv[1]))
print(s["keyframes_created"], s["lost_frames"])' "$run/stats.json")
    echo "| $search | $seed | ${counts% *} | ${counts#* } | $(ate se3) | $(ate sim3) |"
  done
done
