#!/bin/bash
# Map files and localisation only (issue 23), measured on simulated replays of real EuRoC
# trajectories (../shared/data/euroc/groundtruth):
#   1. round trip: a 30 s stereo-inertial map saved, reloaded and saved again is byte-identical;
#   2. relocalisation: map on the first 30 s of a 50 s MH_01 replay, then --localise-only on the
#      next 20 s (which revisits the area) of the same render: frames localised, SE3-aligned
#      ATE of both runs, time of the first pose after the slice's start;
#   3. the same on V1_01 (60 s from 5 s), whose later slice mostly sees walls the map did not;
#   4. size and load time of a 60 s map.
#
#   evaluation/studies/maps/map_files.sh OUT_DIR [PKSLAM]
set -euo pipefail
if [ $# -lt 1 ]; then sed -n '2,12p' "$0"; exit 2; fi
out=$1
root=$(cd "$(dirname "$0")/../../.." && pwd)
pkslam_bin=${2:-$root/build/bin/pkslam}
pkslam() { "$pkslam_bin" --log-level warn "$@"; }
gt_dir=$root/../shared/data/euroc/groundtruth
mkdir -p "$out"
cd "$out"
[ -d mh01_50 ] || pkslam simulate --out mh01_50 --trajectory "$gt_dir/MH_01_easy.txt" \
  --start 0 --duration 50 --seed 1 --quiet
[ -d v101_60 ] || pkslam simulate --out v101_60 --trajectory "$gt_dir/V1_01_easy_original.txt" \
  --start 5 --duration 60 --seed 1 --quiet

ate() {  # ATE RMSE (m) of a run's body trajectory, SE3 alignment
  pkslam eval --gt "$1/mav0/state_groundtruth_estimate0/data.csv" --est "$2/trajectory_body.txt" \
    --align se3 | awk '/^ATE \[m\]/ {print $3}'
}
json() {  # FILE KEY [KEY...]: a value of a stats.json
  /usr/bin/python3 -c 'import json,sys
d = json.load(open(sys.argv[1]))
for k in sys.argv[2:]: d = d[k]
print(d)' "$@"
}

relocalise() {  # SEQ NAME: map on frames 0-599, localise on 600-999
  local seq=$1 name=$2
  pkslam run --dataset "$seq" --sensor stereo-inertial --max-frames 600 --quiet \
    --save-map "$name.pkmap" --out "$name-map" > /dev/null
  pkslam run --dataset "$seq" --sensor stereo-inertial --first-frame 600 --max-frames 400 \
    --load-map "$name.pkmap" --localise-only --quiet --out "$name-localise" > /dev/null
  local frames tracked ate_map ate_loc first t0
  frames=$(json "$name-localise/stats.json" frames)
  tracked=$(json "$name-localise/stats.json" frames_in_trajectory)
  ate_map=$(ate "$seq" "$name-map")
  ate_loc=$(ate "$seq" "$name-localise")
  t0=$(sed -n '602p' "$seq/mav0/cam0/data.csv" | cut -d, -f1)   # frame 600 (after the header)
  first=$(grep -v '^#' "$name-localise/trajectory_body.txt" | head -1 | cut -d' ' -f1)
  /usr/bin/python3 -c "
f,t=$frames,$tracked; a,b=$ate_map,$ate_loc
print(f'$name: localised {t}/{f} frames ({100*t/f:.1f}%), ATE mapping {1e3*a:.2f} mm, '
      f'localise-only {1e3*b:.2f} mm ({b/a:.2f}x), first pose {float($first)-$t0*1e-9:.2f} s after the slice start')"
}

echo "== round trip (30 s stereo-inertial map, MH_01 replay)"
pkslam run --dataset mh01_50 --sensor stereo-inertial --max-frames 600 --quiet \
  --save-map roundtrip.pkmap --out roundtrip-run > /dev/null
pkslam map roundtrip roundtrip.pkmap --dataset mh01_50 | tail -1
echo "== relocalisation into a loaded map (stereo-inertial, localise-only)"
relocalise mh01_50 mh01
relocalise v101_60 v101
echo "== a 60 s map (V1_01 replay): size and load time (3 loads)"
pkslam run --dataset v101_60 --sensor stereo-inertial --quiet --save-map v101_60s.pkmap \
  --out v101-60s > /dev/null
pkslam map info v101_60s.pkmap | tail -1
for i in 1 2 3; do
  pkslam run --dataset v101_60 --sensor stereo-inertial --max-frames 1 --quiet \
    --load-map v101_60s.pkmap --localise-only --out v101-load > /dev/null
  echo "load $i: $(json v101-load/stats.json map_loaded bytes) bytes in" \
    "$(json v101-load/stats.json map_loaded seconds) s"
done
