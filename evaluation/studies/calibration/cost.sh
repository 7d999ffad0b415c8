#!/bin/bash
# Cost of online calibration (issue 36's bar: stereo-inertial real-time factor at most 10% lower
# than `off` on the same render): `pkslam run` with --calibrate off and online, one process at a
# time (nothing else should run: the wall clock is what is measured), unpaced, on each render
# given; prints wall time, real-time factor (sequence duration / wall time), process CPU and
# local mapping's CPU from stats.json, the online / off ratios, and the final adjustment's time.
#   evaluation/studies/calibration/cost.sh PKSLAM OUT RENDER...   (RENDER: render.sh's folders)
set -euo pipefail
if [ $# -lt 3 ]; then sed -n '2,7p' "$0"; exit 2; fi
pk=$(realpath "$1"); out=$2; shift 2
mkdir -p "$out"
printf '%-24s %-7s %8s %6s %8s %8s\n' render mode "wall s" RTF "CPU s" "LM CPU s"
for render in "$@"; do
  name=$(basename "$render")
  for mode in off online; do
    run="$out/${name}_$mode"
    [ -f "$run/stats.json" ] || "$pk" run --dataset "$render" --sensor stereo-inertial \
      --calibrate "$mode" --out "$run" --quiet > "$run.log" 2>&1
  done
  /usr/bin/python3 - "$out/${name}_off/stats.json" "$out/${name}_online/stats.json" "$name" <<'PY'
import json, sys
rows = [json.load(open(p)) for p in sys.argv[1:3]]
for mode, s in zip(("off", "online"), rows):
    print("%-24s %-7s %8.1f %6.2f %8.1f %8.1f" % (sys.argv[3], mode, s["wall_time_s"],
          s["realtime_factor"], s["process_cpu_s"], s["local_mapping_cpu_s"]))
off, on = rows
print("%-24s %-7s %8.2f %6.2f %8.2f %8.2f" % (sys.argv[3], "ratio", on["wall_time_s"] / off["wall_time_s"],
      on["realtime_factor"] / off["realtime_factor"], on["process_cpu_s"] / off["process_cpu_s"],
      on["local_mapping_cpu_s"] / off["local_mapping_cpu_s"]))
t = on["calibration"].get("final_timing")
if t:  # the final adjustment after the last frame (stats.json since 2026-11-29)
    final_s = (t["collect_ms"] + t["solve_ms"] + t["apply_ms"]) / 1e3
    print("%-24s final adjustment %.1f s (covariance %.1f s); online without it: RTF ratio %.2f"
          % (sys.argv[3], final_s, t["covariance_ms"] / 1e3,
             off["wall_time_s"] / (on["wall_time_s"] - final_s)))
PY
done
