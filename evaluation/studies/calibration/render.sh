#!/bin/bash
# Renders the ten sequences of bench/suites/calibration.yaml: five full-length EuRoC
# replays under the euroc realism preset, each with every error source on (NAME_all) and with the
# calibration source off (NAME_calibration_off: the files hold the true calibration; the
# images, IMU and timing are the same draw). Resumes: a rendered sequence is kept.
#
#   evaluation/studies/calibration/render.sh OUT [PKSLAM]
#   PKSLAM_CALIBRATION_RENDERS=OUT build/bin/pkslam bench bench/suites/calibration.yaml \
#       --out bench-calibration --jobs 2
#   python3 evaluation/studies/calibration/calibration_table.py bench-calibration
#
# About 2 GB per sequence, 20 GB in all; 3-6 minutes each on 2 cores.
set -euo pipefail
if [ $# -lt 1 ]; then sed -n '2,12p' "$0"; exit 2; fi
out=$1
root=$(cd "$(dirname "$0")/../../.." && pwd)
pkslam=${2:-$root/build/bin/pkslam}
shared=${PKSLAM_SHARED_DATA:-$root/../shared/data}
# name trajectory seed (the seeds of bench/suites/realism.yaml's replays)
while read -r name trajectory seed; do
  for variant in all calibration_off; do
    dir=$out/${name}_$variant
    [ -f "$dir/sim.yaml" ] && continue
    extra=()
    [ $variant = calibration_off ] && extra=(--realism-off calibration)
    echo "render.sh: $dir"
    rm -rf "$dir.partial"  # an interrupted render (simulate writes only into new folders)
    "$pkslam" simulate --out "$dir.partial" --trajectory "$shared/euroc/groundtruth/$trajectory.txt" \
      --seed "$seed" --realism euroc "${extra[@]}" --no-cloud --quiet
    mv "$dir.partial" "$dir"
  done
done <<'LIST'
MH_01 MH_01_easy 1
MH_02 MH_02_easy 2
V1_01 V1_01_easy_original 3
V1_02 V1_02_medium 4
V2_01 V2_01_easy 5
LIST
