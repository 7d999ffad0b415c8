#!/bin/bash
# KITTI odometry's layout end to end (CTest kitti.run): `pkslam simulate --camera kitti` writes
# OUT/kitti/sequences/00 and poses/00.txt beside the EuRoC folder; `pkslam run` tracks that
# folder with the stereo pair and with the left camera alone; `pkslam eval --kitti-lengths` reads
# the KITTI poses with their times.txt and measures both. Fails when the stereo run tracks fewer
# than 90% of the frames (mono: 60%; it starts after 2 s at rest and needs parallax), or its ATE
# is over 5 cm (stereo, SE(3)) / 10 cm (mono, Sim(3)).
#   tests/kitti/check_kitti_run.sh PKSLAM WORK
set -euo pipefail
pkslam=$1
work=$2
rm -rf "$work"
mkdir -p "$work"
"$pkslam" --log-level warn simulate --out "$work/seq" --camera kitti --motion medium --duration 24 \
  --quality fast --no-cloud --seed 4 --quiet > "$work/simulate.log"
seq="$work/seq/kitti/sequences/00"
test -f "$seq/times.txt" && test -f "$seq/calib.txt" && test -f "$work/seq/kitti/poses/00.txt"
frames=$(wc -l < "$seq/times.txt")
for sensor in stereo mono; do
  "$pkslam" --log-level warn run --dataset "$seq" --sensor "$sensor" --out "$work/$sensor" \
    --deterministic --quiet > "$work/$sensor.log"
  align=se3; bar=0.05; share=0.9
  if [ "$sensor" = mono ]; then align=sim3; bar=0.10; share=0.6; fi
  "$pkslam" eval --gt "$work/seq/kitti/poses/00.txt" --est "$work/$sensor/trajectory.txt" \
    --align "$align" --kitti-lengths 2,4,8 --segments none --json "$work/$sensor.json" \
    > "$work/$sensor.eval"
  /usr/bin/python3 - "$work/$sensor.json" "$frames" "$bar" "$sensor" "$share" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
frames, bar, sensor, share = int(sys.argv[2]), float(sys.argv[3]), sys.argv[4], float(sys.argv[5])
ate, pairs, kitti = r["ate"]["rmse"], r["pairs"], r["kitti"]
print(f"{sensor}: {pairs}/{frames} frames, ATE {ate:.4f} m, KITTI metric "
      f"{kitti['trans_percent']:.3f} % / {kitti['rot_deg_per_100m']:.3f} deg/100 m over "
      f"{kitti['segments']} segments")
ok = pairs >= share * frames and ate < bar and kitti["segments"] > 0
sys.exit(0 if ok else 1)
PY
done
echo "kitti ok"
