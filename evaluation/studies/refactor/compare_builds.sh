#!/bin/bash
# Does a refactor change nothing? Runs two pkslam binaries (before / after) on the same
# simulated sequences and compares their --deterministic outputs byte for byte (md5), then
# times stereo-inertial on the demo sequence (3 runs each, alternating, same sitting).
#
#   evaluation/studies/refactor/compare_builds.sh BEFORE_BIN AFTER_BIN OUT_DIR
#
# Sequences (made with AFTER_BIN's simulator when missing, from ../shared's V1_02 replay):
#   OUT_DIR/seq30   30 s EuRoC stereo+IMU replay of V1_02_medium from 5 s, seed 1
#   OUT_DIR/rgbd30  30 s TUM RGB-D sequence, medium random motion, seed 3
#   OUT_DIR/demo20  the demo's 20 s sequence (scripts/demo)
# Build BEFORE_BIN from the earlier commit, e.g. `git checkout <commit> && scripts/build`.
set -euo pipefail
if [ $# -ne 3 ]; then sed -n '2,12p' "$0"; exit 2; fi
before=$(realpath "$1"); after=$(realpath "$2"); out=$3
root=$(cd "$(dirname "$0")/../../.." && pwd)
replay="$root/../shared/data/euroc/groundtruth/V1_02_medium.txt"
mkdir -p "$out"
[ -d "$out/seq30" ] || "$after" simulate --out "$out/seq30" --trajectory "$replay" --start 5 \
  --duration 30 --seed 1 --quiet
[ -d "$out/rgbd30" ] || "$after" simulate --out "$out/rgbd30" --rgbd --motion medium \
  --duration 30 --seed 3 --quiet
[ -d "$out/demo20" ] || "$after" simulate --out "$out/demo20" --trajectory "$replay" --start 5 \
  --duration 20 --seed 1 --quiet

echo "== --deterministic outputs (md5 of trajectory[_body].txt keyframes.txt sparse_model.txt)"
status=0
for run in seq30:stereo seq30:stereo-inertial seq30:mono-inertial seq30:mono rgbd30:rgbd; do
  seq=${run%%:*}; sensor=${run#*:}
  for which in before after; do
    bin=$before; [ $which = after ] && bin=$after
    [ -f "$out/$which/$seq-$sensor/stats.json" ] ||
      "$bin" run --dataset "$out/$seq" --sensor "$sensor" --deterministic --quiet \
        --out "$out/$which/$seq-$sensor" > /dev/null 2>&1
  done
  # Body trajectories exist for inertial runs only.
  for f in trajectory_body.txt trajectory.txt keyframes.txt sparse_model.txt; do
    [ -f "$out/before/$seq-$sensor/$f" ] || [ -f "$out/after/$seq-$sensor/$f" ] || continue
    [ "$f" = trajectory.txt ] && [ -f "$out/before/$seq-$sensor/trajectory_body.txt" ] && continue
    b=$(md5sum < "$out/before/$seq-$sensor/$f" | cut -c1-32 || echo missing)
    a=$(md5sum < "$out/after/$seq-$sensor/$f" | cut -c1-32 || echo missing)
    verdict=identical; [ "$a" = "$b" ] || { verdict=DIFFERENT; status=1; }
    printf '%-22s %-20s %s %s %s\n' "$seq $sensor" "$f" "$b" "$a" "$verdict"
  done
done

echo "== stereo-inertial real-time factor on demo20 (sequence s / wall s; 3 runs each)"
for i in 1 2 3; do
  for which in before after; do
    bin=$before; [ $which = after ] && bin=$after
    rm -rf "$out/speed/$which-$i"
    "$bin" run --dataset "$out/demo20" --sensor stereo-inertial --quiet \
      --out "$out/speed/$which-$i" > /dev/null 2>&1
    python3 -c "import json,sys; d=json.load(open(sys.argv[1])); \
print(f\"{sys.argv[2]:6s} run {sys.argv[3]}: realtime factor {d['realtime_factor']:.2f}, wall {d['wall_time_s']:.1f} s\")" \
      "$out/speed/$which-$i/stats.json" "$which" "$i"
  done
done
exit $status
