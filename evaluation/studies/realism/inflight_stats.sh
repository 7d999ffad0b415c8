#!/bin/bash
# Does the euroc preset look like the real Vicon room in flight and before take-off? (issue 38,
# item 1.) Renders two replays of the real V1_01 ground truth under the preset, 40-100 s (in
# flight) and 0-3.5 s (before take-off), and measures every 5th cam0 frame with
# ../shared/tools/image_stats.py: the take-off view against the 95 real static frames
# (../shared/data/euroc/V1_01_easy_static), the in-flight view against the real in-flight
# numbers (four real in-flight V1_01 stereo pairs measured with the same tool, quoted in
# issue 38: FAST-20 corners median about 1,600, mean gradient about 54, 9% saturated, 47% of
# 32-px cells empty). Re-renders only when OUT/<view>/sim.yaml is missing.
#
#   evaluation/studies/realism/inflight_stats.sh OUT [PKSLAM] [SEED]
set -euo pipefail
if [ $# -lt 1 ]; then sed -n '2,12p' "$0"; exit 2; fi
out=$1
root=$(cd "$(dirname "$0")/../../.." && pwd)
pkslam=${2:-$root/build/bin/pkslam}
seed=${3:-1}
shared=${PKSLAM_SHARED_DATA:-$root/../shared/data}
tools=${PKSLAM_SHARED_TOOLS:-$root/../shared/tools}
gt=$shared/euroc/groundtruth/V1_01_easy_original.txt
mkdir -p "$out"
render() {  # name start duration
  [ -f "$out/$1/sim.yaml" ] && return
  rm -rf "$out/$1"
  "$pkslam" simulate --out "$out/$1" --trajectory "$gt" --start "$2" --duration "$3" \
    --seed "$seed" --realism euroc --no-cloud --quiet > /dev/null
}
render takeoff 0 3.5
render inflight 40 60
echo "== take-off view (0-3.5 s) against the real static frames"
/usr/bin/python3 "$tools/image_stats.py" "$shared/euroc/V1_01_easy_static" "$out/takeoff"
echo "== in flight (40-100 s, every 5th frame)"
/usr/bin/python3 "$tools/image_stats.py" "$out/inflight" | tee "$out/inflight_stats.txt"
/usr/bin/python3 - "$out/inflight_stats.txt" <<'PY'
import sys
real = {"fast20_median": 1600, "grad_mean": 54.0, "saturated_pct": 9.0, "empty_cells_pct": 47.0}
cols = ["fast20_median", "grad_mean", "saturated_pct", "dark_pct", "empty_cells_pct"]
for line in open(sys.argv[1]):
    parts = line.split()
    if len(parts) == 7 and parts[1].isdigit():
        values = dict(zip(cols, map(float, parts[2:])))
        print("ratio to the real in-flight frames: " + ", ".join(
            f"{k} {values[k] / v:.2f}x" for k, v in real.items()))
PY
