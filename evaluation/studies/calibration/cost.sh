#!/bin/bash
# Cost of online calibration (issue 36's bar: stereo-inertial real-time factor at most 10% lower
# than `off` on the same render): `pkslam run` with --calibrate off and online, one process at a
# time (nothing else should run: the wall clock is what is measured), unpaced, on each render
# given; prints wall time, real-time factor (sequence duration / wall time), process CPU and
# local mapping's CPU from stats.json, the online / off ratios, and the final adjustment's time.
#   evaluation/studies/calibration/cost.sh PKSLAM OUT RENDER...   (RENDER: render.sh's folders)
#   ONLINE_ARGS='--calibrate-thread thread' REPEAT=3 evaluation/studies/calibration/cost.sh ...
# ONLINE_ARGS: added to the online runs; REPEAT: off/online pairs per render, interleaved (the
# machine's own spread is several percent; OUT/NAME_MODE_K for K > 1), ratios of the medians.
set -euo pipefail
if [ $# -lt 3 ]; then sed -n '2,7p' "$0"; exit 2; fi
pk=$(realpath "$1"); out=$2; shift 2
mkdir -p "$out"
printf '%-24s %-7s %8s %6s %8s %8s\n' render mode "wall s" RTF "CPU s" "LM CPU s"
repeat=${REPEAT:-1}
read -r -a online_args <<< "${ONLINE_ARGS:-}"
for render in "$@"; do
  name=$(basename "$render")
  for k in $(seq 1 "$repeat"); do
    suffix=""; [ "$k" -gt 1 ] && suffix="_$k"
    for mode in off online; do
      run="$out/${name}_$mode$suffix"
      extra=(); [ $mode = online ] && extra=("${online_args[@]}")
      [ -f "$run/stats.json" ] || "$pk" run --dataset "$render" --sensor stereo-inertial \
        --calibrate "$mode" "${extra[@]}" --out "$run" --quiet > "$run.log" 2>&1
    done
  done
  /usr/bin/python3 - "$out" "$name" "$repeat" <<'PY'
import json, statistics, sys
out, name, repeat = sys.argv[1], sys.argv[2], int(sys.argv[3])
def load(mode, k):
    return json.load(open("%s/%s_%s%s/stats.json" % (out, name, mode, "" if k == 1 else "_%d" % k)))
runs = {m: [load(m, k) for k in range(1, repeat + 1)] for m in ("off", "online")}
for mode in ("off", "online"):
    for s in runs[mode]:
        print("%-24s %-7s %8.1f %6.2f %8.1f %8.1f" % (name, mode, s["wall_time_s"],
              s["realtime_factor"], s["process_cpu_s"], s["local_mapping_cpu_s"]))
med = {m: {key: statistics.median(s[key] for s in runs[m]) for key in
           ("wall_time_s", "realtime_factor", "process_cpu_s", "local_mapping_cpu_s")}
       for m in runs}
off, on = med["off"], med["online"]
print("%-24s %-7s %8.2f %6.2f %8.2f %8.2f   (medians of %d)" % (name, "ratio",
      on["wall_time_s"] / off["wall_time_s"], on["realtime_factor"] / off["realtime_factor"],
      on["process_cpu_s"] / off["process_cpu_s"],
      on["local_mapping_cpu_s"] / off["local_mapping_cpu_s"], repeat))
c = runs["online"][0]["calibration"]
t = c.get("final_timing")
if t:  # the final adjustment after the last frame (stats.json since 2026-11-29)
    final_s = (t["collect_ms"] + t["solve_ms"] + t["apply_ms"]) / 1e3
    print("%-24s solved in %s; final adjustment %.1f s (covariance %.1f s); without it: RTF ratio %.2f"
          % (name, c.get("solved_in", "unrecorded"), final_s, t["covariance_ms"] / 1e3,
             runs["off"][0]["wall_time_s"] / (runs["online"][0]["wall_time_s"] - final_s)))
PY
done
