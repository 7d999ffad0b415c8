#!/bin/bash
# Does an offline run's accuracy depend on the machine? (issue 37, item 7.) Three realistic 60 s
# replays (V1_02, V1_03, V2_02 under the euroc realism preset), SENSORS (default mono-inertial
# and stereo-inertial), COUPLINGS (default "default lockstep"), each on CORES (default "0 0-1":
# one core, taskset -c 0, and two), RUNS runs per cell (default 3) with seeds 1..RUNS.
# Couplings: default (the offline default of the build), lockstep, live and free (--mapping-sync),
# cpu (live emulation on the mapping thread's CPU clock,
# the default before the work clock), cpu-slow (the CPU clock at pace 4: what the CPU clock does
# on a machine twice as slow as this one). One line per run in OUT/cores.tsv (ATE of
# trajectory_body.txt, SE3; frames with a pose; real-time factor; suspect flag; commit).
# Resumes: a finished run (stats.json) is not run again.
#
#   [RUNS=3] [COUPLINGS=...] [CORES=...] [SENSORS=...] evaluation/studies/coupling/cores.sh OUT [PKSLAM]
#   /usr/bin/python3 evaluation/studies/coupling/cores_table.py OUT/cores.tsv
set -euo pipefail
if [ $# -lt 1 ]; then sed -n '2,16p' "$0"; exit 2; fi
out=$1
root=$(cd "$(dirname "$0")/../../.." && pwd)
pkslam=${2:-$root/build/bin/pkslam}
runs=${RUNS:-3}
couplings=${COUPLINGS:-default lockstep}
core_sets=${CORES:-0 0-1}
sensors=${SENSORS:-mono-inertial stereo-inertial}
shared=${PKSLAM_SHARED_DATA:-$root/../shared/data}
commit=$(git -C "$root" rev-parse --short HEAD)
mkdir -p "$out/runs"
# name trajectory start seed
replays="V1_02 V1_02_medium 0 4
V1_03 V1_03_difficult 0 6
V2_02 V2_02_medium 0 7"
while read -r name trajectory start seed; do
  [ -f "$out/$name/sim.yaml" ] && continue
  echo "cores.sh: rendering $name"
  rm -rf "$out/$name.partial"  # an interrupted render (simulate writes only into new folders)
  "$pkslam" simulate --out "$out/$name.partial" --trajectory "$shared/euroc/groundtruth/$trajectory.txt" \
    --start "$start" --duration 60 --seed "$seed" --realism euroc --no-cloud --quiet > /dev/null
  mv "$out/$name.partial" "$out/$name"
done <<< "$replays"

tsv=$out/cores.tsv
[ -f "$tsv" ] || printf 'replay\tsensor\tcoupling\tcores\trun\tate_m\tposed\tframes\trealtime\tsuspect\texit\tcommit\n' > "$tsv"
while read -r name trajectory start seed; do
  for sensor in $sensors; do
    for coupling in $couplings; do
      for cores in $core_sets; do
        for run in $(seq 1 "$runs"); do
          dir=$out/runs/$name-$sensor-$coupling-c${cores/-/}-r$run
          [ -f "$dir/stats.json" ] && continue
          case $coupling in
            default) extra=() ;;
            lockstep) extra=(--mapping-sync lockstep) ;;
            live) extra=(--mapping-sync live) ;;
            free) extra=(--mapping-sync free) ;;
            cpu) extra=(--live-clock cpu) ;;
            cpu-slow) extra=(--live-clock cpu --live-pace 4) ;;
            *) echo "cores.sh: unknown coupling '$coupling' (default|lockstep|live|free|cpu|cpu-slow)" >&2; exit 2 ;;
          esac
          set +e
          taskset -c "$cores" "$pkslam" --log-level warn run --dataset "$out/$name" --sensor "$sensor" \
            --seed "$run" ${extra[@]+"${extra[@]}"} --quiet --out "$dir" > "$dir.log" 2>&1
          code=$?
          set -e
          ate=$("$pkslam" eval --gt "$out/$name/mav0/state_groundtruth_estimate0/data.csv" \
            --est "$dir/trajectory_body.txt" 2>/dev/null | awk '/^ATE \[m\]/ {print $3}')
          /usr/bin/python3 - "$dir/stats.json" <<PY >> "$tsv"
import json, sys
try:
    s = json.load(open(sys.argv[1]))
except OSError:
    s = {}
print("\t".join(map(str, ["$name", "$sensor", "$coupling", "$cores", $run, "${ate:-nan}",
    s.get("frames_in_trajectory", 0), s.get("frames", 0), round(s.get("realtime_factor", 0), 3),
    s.get("estimate", {}).get("suspect", ""), $code, "$commit"])))
PY
          echo "cores.sh: $(tail -1 "$tsv")"
        done
      done
    done
  done
done <<< "$replays"
