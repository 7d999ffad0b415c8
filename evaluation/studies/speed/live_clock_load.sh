#!/bin/bash
# Does a loaded machine change what an offline mono-inertial run computes? Runs CONCURRENT
# mono-inertial runs at once (more runs than cores = load), once per clock in CLOCKS (default
# "wall cpu"; "work" is the offline default; docs/speed.md "The live emulation's clock"), and
# prints per run the losses for good and the ATE after Sim(3).
#
#   [CLOCKS="wall cpu work"] evaluation/studies/speed/live_clock_load.sh PKSLAM DATASET OUT CONCURRENT SEED...
#
# DATASET: e.g. a full V1_02 replay,
#   pkslam simulate --trajectory ../shared/data/euroc/groundtruth/V1_02_medium.txt \
#       --realism euroc --no-cloud --seed 400 --out v102_400
set -euo pipefail
if [ $# -lt 5 ]; then sed -n 2,12p "$0"; exit 1; fi
pkslam=$1 dataset=$2 out=$3 concurrent=$4
shift 4
seeds=("$@")
gt=$dataset/mav0/state_groundtruth_estimate0/data.csv
mkdir -p "$out"
for clock in ${CLOCKS:-wall cpu}; do
  for ((i = 0; i < ${#seeds[@]}; i += concurrent)); do
    batch=("${seeds[@]:i:concurrent}")
    for s in "${batch[@]}"; do
      "$pkslam" run --dataset "$dataset" --sensor mono-inertial --selector orbslam3 --seed "$s" \
        --live-clock "$clock" --quiet --out "$out/${clock}_$s" > /dev/null 2>&1 &
    done
    wait
    for s in "${batch[@]}"; do
      losses=$(grep -c 'tracking lost' "$out/${clock}_$s/run.log" || true)
      ate=$("$pkslam" eval --gt "$gt" --est "$out/${clock}_$s/trajectory_body.txt" --align sim3 |
        awk '/^ATE \[m\]/ {print $3}')
      echo "clock $clock concurrent ${#batch[@]} seed $s: losses $losses, ATE $ate m"
    done
  done
done
