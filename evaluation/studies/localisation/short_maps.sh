#!/bin/bash
# Localisation on short maps (issue 37): for three simulated replays of real EuRoC flights
# (../shared/data/euroc/groundtruth, 40 s from take-off), a stereo-inertial map of the first
# 10 s and of the first 20 s, then --localise-only on the rest of the same render. Per map:
# frames with a pose after the map ends, how many of them against the map (the rest by visual
# odometry), seconds to the first pose, stretches without a pose, and the SE3-aligned ATE of the
# frames with a pose. Results in OUT/short_maps.tsv with the commit.
#
#   evaluation/studies/localisation/short_maps.sh OUT_DIR [PKSLAM]
set -euo pipefail
if [ $# -lt 1 ]; then sed -n '2,9p' "$0"; exit 2; fi
out=$1
root=$(cd "$(dirname "$0")/../../.." && pwd)
pkslam_bin=${2:-$root/build/bin/pkslam}
pkslam() { "$pkslam_bin" --log-level warn "$@"; }
gt_dir=$root/../shared/data/euroc/groundtruth
mkdir -p "$out"
cd "$out"
# name, ground-truth file, start (s: just before take-off)
replays="v102 V1_02_medium.txt 2
v201 V2_01_easy.txt 2
mh01 MH_01_easy.txt 20"
while read -r name file start; do
  [ -f "$name/sim.yaml" ] || pkslam simulate --out "$name" --trajectory "$gt_dir/$file" \
    --start "$start" --duration 40 --seed 1 --quality fast --quiet --no-cloud > /dev/null
done <<< "$replays"

json() {  # FILE KEY [KEY...]
  /usr/bin/python3 -c 'import json,sys
d = json.load(open(sys.argv[1]))
for k in sys.argv[2:]: d = d[k]
print(d)' "$@"
}
commit=$(git -C "$root" rev-parse --short HEAD)
printf 'replay\tmap_s\tframes\tlocalised\tshare\tin_map\todometry\tfirst_s\tgaps\tunrecovered\tate_mm\tcommit\n' \
  > short_maps.tsv
while read -r name file start; do
  for map_s in 10 20; do
    frames=$((map_s * 20))
    pkslam run --dataset "$name" --sensor stereo-inertial --max-frames "$frames" --quiet \
      --save-map "$name-$map_s.pkmap" --out "$name-$map_s-map" > /dev/null || true
    pkslam run --dataset "$name" --sensor stereo-inertial --first-frame "$frames" \
      --load-map "$name-$map_s.pkmap" --localise-only --quiet --out "$name-$map_s-loc" \
      > /dev/null || true
    s="$name-$map_s-loc/stats.json"
    ate=$(pkslam eval --gt "$name/mav0/state_groundtruth_estimate0/data.csv" \
      --est "$name-$map_s-loc/trajectory_body.txt" 2>/dev/null | awk '/^ATE \[m\]/ {print $3}')
    /usr/bin/python3 -c "
f, l = $(json "$s" localisation frames), $(json "$s" localisation localised)
vo = $(json "$s" localisation visual_odometry 2>/dev/null || echo 0)
print('\t'.join(map(str, ['$name', $map_s, f, l, f'{100 * l / f:.1f}%', f'{100 * (l - vo) / f:.1f}%', vo,
      '$(json "$s" localisation first_localised_after_s)', $(json "$s" localisation gaps),
      $(json "$s" localisation unrecovered_frames),
      f'{1e3 * float(\"${ate:-nan}\"):.2f}', '$commit'])))" >> short_maps.tsv
  done
done <<< "$replays"
column -t -s $'\t' short_maps.tsv
