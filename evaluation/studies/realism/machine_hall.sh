#!/bin/bash
# How far is the machine hall, and what does its depth cost the stereo-inertial peer? (issue 38,
# item 2.) Renders one machine-hall replay under the euroc preset with the preset's scene (or
# SCENE), runs ORB-SLAM3 (scripts/run_peer) and pkslam stereo-inertially RUNS times each and
# prints, per run, the ATE after SE(3) alignment (as the harness and the published numbers), the
# scale a Sim(3) alignment finds (a stereo depth bias shows as a scale error) and the median depth
# of pkslam's map points as its keyframes saw them (map_depth.py). Extra simulate arguments after
# the seed (e.g. --realism-off calibration) give the diagnostic renders of docs/realism.md.
# Resumes: a finished render or run is kept.
#
#   evaluation/studies/realism/machine_hall.sh OUT [SCENE|preset] [SEQUENCE] [SEED] [simulate args...]
#   (defaults: preset, MH_02_easy, seed 2 as bench/suites/realism.yaml; RUNS=1)
set -euo pipefail
if [ $# -lt 1 ]; then sed -n '2,13p' "$0"; exit 2; fi
out=$1 scene=${2:-preset} seq=${3:-MH_02_easy} seed=${4:-2}
shift $(($# >= 4 ? 4 : $#))
root=$(cd "$(dirname "$0")/../../.." && pwd)
pkslam=${PKSLAM:-$root/build/bin/pkslam}
shared=${PKSLAM_SHARED_DATA:-$root/../shared/data}
runs=${RUNS:-1}
data=$out/data
mkdir -p "$out"
if [ ! -f "$data/sim.yaml" ]; then
  rm -rf "$data"
  scene_args=()
  [ "$scene" = preset ] || scene_args=(--scene "$scene")
  echo "== render $seq" >&2
  "$pkslam" simulate --out "$data" --trajectory "$shared/euroc/groundtruth/$seq.txt" --seed "$seed" \
    --realism euroc --no-cloud --quiet "${scene_args[@]}" "$@" > "$out/sim.log" 2>&1
fi
gt=$data/mav0/state_groundtruth_estimate0/data.csv
measure() {  # label estimate
  local se3 sim3
  se3=$("$pkslam" eval --gt "$gt" --est "$2" --align se3 --json "$2.se3.json" > /dev/null 2>&1 &&
        /usr/bin/python3 -c "import json,sys; print('%.4f' % json.load(open(sys.argv[1]))['ate']['rmse'])" "$2.se3.json" || echo fail)
  sim3=$("$pkslam" eval --gt "$gt" --est "$2" --align sim3 --json "$2.sim3.json" > /dev/null 2>&1 &&
         /usr/bin/python3 -c "import json,sys; print('%.4f' % json.load(open(sys.argv[1]))['scale'])" "$2.sim3.json" || echo fail)
  printf '%-14s ATE %s m  Sim(3) scale %s\n' "$1" "$se3" "$sim3"
}
for r in $(seq 1 "$runs"); do
  [ -f "$out/peer$r/f_peer.txt" ] || "$root/scripts/run_peer" "$data" stereo-inertial "$out/peer$r" > "$out/peer$r.log" 2>&1 || true
  [ -f "$out/pkslam$r/trajectory_body.txt" ] ||
    "$pkslam" run --dataset "$data" --sensor stereo-inertial --out "$out/pkslam$r" --quiet > "$out/pkslam$r.log" 2>&1 || true
  if [ -f "$out/peer$r/f_peer.txt" ]; then measure "peer run $r" "$out/peer$r/f_peer.txt"; else echo "peer run $r failed"; fi
  if [ -f "$out/pkslam$r/trajectory_body.txt" ]; then
    measure "pkslam run $r" "$out/pkslam$r/trajectory_body.txt"
    /usr/bin/python3 "$root/evaluation/studies/realism/map_depth.py" "$out/pkslam$r"
  else
    echo "pkslam run $r failed"
  fi
done
grep -h 'frames/s' "$out/sim.log" || true
