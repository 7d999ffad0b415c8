#!/usr/bin/env bash
# Offline monocular speed and accuracy, live emulation (the default) against lock-step (the
# coupling before issue 19, still --mapping-sync lockstep) and the ORB-SLAM3 peer, on the
# 40 s V1_02 replay (euroc realism preset): docs/speed.md.
#   evaluation/studies/speed/mono_offline.sh OUT [RUNS]
# Needs build/bin/pkslam, ../shared/data (or $PKSLAM_SHARED_DATA) and, for the peer rows, the
# peer built (../shared/tools/peer/README.md; skipped when $PEER/bin is missing). Runs one at a
# time: timings need an idle machine. Prints one row per run and the medians per configuration.
set -euo pipefail
root=$(cd "$(dirname "$0")/../../.." && pwd)
out=${1:?usage: mono_offline.sh OUT [RUNS]}
runs=${2:-3}
pkslam=$root/build/bin/pkslam
shared=${PKSLAM_SHARED_DATA:-$root/../shared/data}
seq=$out/V1_02_40s
mkdir -p "$out"
if [ ! -f "$seq/mav0/cam0/data.csv" ]; then
  "$pkslam" simulate --trajectory "$shared/euroc/groundtruth/V1_02_medium.txt" --duration 40 \
    --out "$seq" --no-cloud --quiet
fi
gt=$seq/mav0/state_groundtruth_estimate0/data.csv
rows=$out/rows.txt
: > "$rows"
score() {  # score NAME RUN_DIR: ATE of the camera trajectory (Sim(3) for mono, SE(3) for mono-inertial)
  local name=$1 dir=$2 align=sim3
  case $name in *mono-inertial*) align=se3 ;; esac
  "$pkslam" eval --gt "$gt" --est "$dir/trajectory.txt" --body-from-camera "$dir/body_from_camera.txt" \
    --align "$align" --json "$dir/ate.json" > /dev/null
  /usr/bin/python3 - "$name" "$dir" >> "$rows" <<'PY'
import json, sys
name, d = sys.argv[1:3]
a = json.load(open(d + '/ate.json'))['ate']['rmse']
s = json.load(open(d + '/stats.json'))
print(name, '%.2f' % s['realtime_factor'], s.get('lost_frames', 0), '%.1f' % s.get('median_tracking_ms', 0),
      s.get('keyframes_created', s.get('keyframes', 0)), '%.2f' % (1e3 * a))
PY
}
for sensor in mono mono-inertial; do
  for k in $(seq 1 "$runs"); do
    for sync in live lockstep; do
      dir=$out/$sensor-$sync-$k
      "$pkslam" run --dataset "$seq" --sensor "$sensor" --out "$dir" --seed "$k" --mapping-sync "$sync" --quiet
      score "$sensor-$sync" "$dir"
    done
    if [ -d "${PEER:-/tmp/peer}/bin" ]; then
      dir=$out/$sensor-peer-$k
      mkdir -p "$dir"
      if "$root/scripts/run_peer" "$seq" "$sensor" "$dir" > "$dir/peer.log" 2>&1 && [ -s "$dir/traj_tum.txt" ]; then
        # Its trajectory (cam0 poses for mono, body poses for mono-inertial), the cam0 extrinsic
        # it read, and stats in pkslam's keys: the realtime factor over its frame loop (the sum
        # of its per-frame Track*() times, track_times.txt), as `pkslam bench` imports it.
        /usr/bin/python3 - "$dir" "$seq" "$sensor" <<'PY'
import json, re, sys
d, seq, sensor = sys.argv[1:4]
times = sorted(float(l.split()[1]) for l in open(d + '/track_times.txt') if l.strip())
stamps = [int(l.split(',')[0]) for l in open(seq + '/mav0/cam0/data.csv') if l[0].isdigit()]
duration = (stamps[-1] - stamps[0]) * 1e-9
poses = [float(l.split()[0]) for l in open(d + '/traj_tum.txt') if l.strip() and l[0] != '#']
after_first = sum(1 for t in stamps if t * 1e-9 >= poses[0] - 1e-4)  # frames from its first pose on
json.dump({'realtime_factor': duration / sum(times), 'median_tracking_ms': 1e3 * times[len(times) // 2],
           'keyframes_created': sum(1 for _ in open(d + '/kf_tum.txt')),
           'lost_frames': max(after_first - len(poses), 0)}, open(d + '/stats.json', 'w'))
t = open(seq + '/mav0/cam0/sensor.yaml').read()
v = [float(x) for x in re.search(r'T_BS:.*?data:\s*\[([^\]]*)\]', t, re.S).group(1).split(',')]
with open(d + '/body_from_camera.txt', 'w') as f:
    for r in range(4):
        f.write(' '.join('%.12g' % x for x in v[4 * r:4 * r + 4]) + '\n')
PY
        if [ "$sensor" = mono ]; then
          cp "$dir/traj_tum.txt" "$dir/trajectory.txt"
          score "$sensor-peer" "$dir"
        else
          # Body poses: compare them with the body ground truth directly.
          "$pkslam" eval --gt "$gt" --est "$dir/traj_tum.txt" --align se3 --json "$dir/ate.json" > /dev/null
          /usr/bin/python3 - "$sensor-peer" "$dir" >> "$rows" <<'PY'
import json, sys
name, d = sys.argv[1:3]
a = json.load(open(d + '/ate.json'))['ate']['rmse']
s = json.load(open(d + '/stats.json'))
print(name, '%.2f' % s['realtime_factor'], s['lost_frames'], '%.1f' % s['median_tracking_ms'], s['keyframes_created'], '%.2f' % (1e3 * a))
PY
        fi
      else
        echo "$sensor-peer failed - - - -" >> "$rows"
      fi
    fi
  done
done
echo "config realtime_factor lost_frames median_tracking_ms keyframes_created ate_mm"
cat "$rows"
/usr/bin/python3 - "$rows" <<'PY'
import statistics, sys, collections
by = collections.defaultdict(list)
for line in open(sys.argv[1]):
    w = line.split()
    by[w[0]].append(w[1:])
print('\nmedians: config, realtime_factor, ate_mm (runs)')
for k, v in by.items():
    ok = [r for r in v if r[0] != 'failed' and r[-1] != '-']
    if not ok:
        print(k, 'all failed'); continue
    print(k, '%.2f' % statistics.median(float(r[0]) for r in ok), '%.2f' % statistics.median(float(r[-1]) for r in ok),
          '(%d of %d ok)' % (len(ok), len(v)))
PY
