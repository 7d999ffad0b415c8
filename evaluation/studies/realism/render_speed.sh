#!/bin/bash
# Rendering speed of pkslam simulate (issue 38: at least 20 stereo frames per second end to end
# on the 2-core machine), optionally against an earlier build: renders the same replays with
# each executable in turn, ROUNDS times, prints the speed each render reports (the last line of
# `pkslam simulate`) and checks that the builds wrote the same bytes. Run it with the machine
# otherwise idle: the number is wall-clock frames per second.
#
#   evaluation/studies/realism/render_speed.sh OUT [PKSLAM [EARLIER_PKSLAM]]
#   (default PKSLAM: build/bin/pkslam; ROUNDS=2; DURATION=20 seconds of each replay from 20 s)
# Replays: MH_02 (the machine hall, the bar's reference in docs/realism.md) and V1_01 (the
# Vicon room), the euroc preset with everything on, seeds as bench/suites/realism.yaml.
set -euo pipefail
if [ $# -lt 1 ]; then sed -n '2,11p' "$0"; exit 2; fi
out=$1
root=$(cd "$(dirname "$0")/../../.." && pwd)
new=${2:-$root/build/bin/pkslam}
old=${3:-}
shared=${PKSLAM_SHARED_DATA:-$root/../shared/data}
rounds=${ROUNDS:-2} duration=${DURATION:-20}
mkdir -p "$out"
builds=(new)
[ -n "$old" ] && builds+=(old)
for seq_seed in MH_02_easy:2 V1_01_easy_original:3; do
  seq=${seq_seed%:*} seed=${seq_seed#*:}
  for r in $(seq 1 "$rounds"); do
    for b in "${builds[@]}"; do
      exe=$new
      [ "$b" = old ] && exe=$old
      dir=$out/$seq-$b-$r
      rm -rf "$dir"
      "$exe" simulate --out "$dir" --trajectory "$shared/euroc/groundtruth/$seq.txt" \
        --seed "$seed" --start 20 --duration "$duration" --realism euroc --no-cloud --quiet \
        > "$dir.log" 2>&1
      printf '%-22s %-3s round %d: %s\n' "$seq" "$b" "$r" "$(tail -1 "$dir.log" | sed 's/^ *//')"
    done
    if [ -n "$old" ]; then
      if diff -r -q "$out/$seq-new-$r" "$out/$seq-old-$r" > /dev/null; then
        echo "$seq round $r: the two builds wrote identical files"
      else
        echo "$seq round $r: the builds' files DIFFER" >&2
        exit 1
      fi
    fi
  done
done
