#!/bin/bash
# The dense-cloud table of docs/dense.md: for 20 s replays of three EuRoC ground truths
# (../shared; V1_01 from 30 s, V1_02 and V2_01 from 20 s, ideal rendering) and a random medium
# flight, stereo runs with the orbslam3 and pks selectors, `pkslam dense` with its defaults, and
# cloud-compare: surface accuracy against reference_cloud.ply, completeness against the full
# room and against reference_observed.ply (3 m), the run's ATE (SE(3)).
#
#   evaluation/studies/dense/selector_clouds.sh PKSLAM OUT_DIR
set -euo pipefail
if [ $# -ne 2 ]; then sed -n '2,9p' "$0"; exit 2; fi
pk=$(realpath "$1"); out=$2
root=$(cd "$(dirname "$0")/../../.." && pwd)
gt="$root/../shared/data/euroc/groundtruth"
mkdir -p "$out"
declare -A seqs=(
  [sim_med_20s]="--motion medium --duration 20 --seed 1"
  [V1_01_s30_d20]="--trajectory $gt/V1_01_easy_original.txt --start 30 --duration 20"
  [V1_02_s20_d20]="--trajectory $gt/V1_02_medium.txt --start 20 --duration 20"
  [V2_01_s20_d20]="--trajectory $gt/V2_01_easy.txt --start 20 --duration 20"
)
echo "| sequence | selector | keyframes | dense points | accuracy mean / median (cm) | within 5 cm | completeness full room | observed 3 m | ATE (cm) |"
echo "|---|---|---|---|---|---|---|---|---|"
for name in sim_med_20s V1_01_s30_d20 V1_02_s20_d20 V2_01_s20_d20; do
  seq="$out/$name"
  # shellcheck disable=SC2086
  [ -d "$seq/mav0" ] || "$pk" simulate --out "$seq" --realism ideal ${seqs[$name]} --quiet > /dev/null
  truth="$seq/mav0/state_groundtruth_estimate0/data.csv"
  for selector in orbslam3 pks; do
    run="$out/${name}_$selector"
    [ -f "$run/stats.json" ] || "$pk" run --dataset "$seq" --sensor stereo --selector "$selector" \
      --out "$run" --quiet > /dev/null
    "$pk" dense --run "$run" --dataset "$seq" --out "$run/dense.ply" --json "$run/dense.json" \
      --quiet > /dev/null
    "$pk" cloud-compare --cloud "$run/dense.ply" --ref "$seq/reference_cloud.ply" \
      --observed-ref "$seq/reference_observed.ply" --align-run "$run" --gt "$truth" \
      --json "$run/compare.json" > /dev/null
    "$pk" eval --gt "$truth" --est "$run/trajectory_body.txt" --json "$run/ate.json" > /dev/null
    /usr/bin/python3 - "$name" "$selector" "$run" <<'PY'
import json, sys
name, selector, run = sys.argv[1:]
c = json.load(open(f"{run}/compare.json"))
d = json.load(open(f"{run}/dense.json"))
s = json.load(open(f"{run}/stats.json"))
ate = json.load(open(f"{run}/ate.json"))["ate"]["rmse"]
a = c["surface_accuracy"] or c["accuracy"]
print(f"| {name} | {selector} | {s['keyframes']} | {d['points'] / 1e6:.2f} M | "
      f"{100 * a['mean']:.2f} / {100 * a['median']:.2f} | {100 * a['within']['0.05']:.1f}% | "
      f"{100 * c['completeness']:.1f}% | {100 * c['completeness_observed'][0]['completeness']:.1f}% | "
      f"{100 * ate:.2f} |")
PY
  done
done
