#!/bin/bash
# TUM-VI's folders end to end (CTest tumvi.run): `pkslam simulate --camera tumvi` renders TUM-VI's
# 512x512 Kannala-Brandt fisheye pair at 20 Hz with its IMU noise and writes dso/camchain.yaml,
# dso/imu_config.yaml and mav0/mocap0/data.csv; with EuRoC's sensor.yaml files and ground truth
# removed the folder has TUM-VI's layout, which `pkslam run` reads through the camchain.
# Stereo-inertial must track at least 95% of the frames with an ATE under 3 cm (against
# mocap0), monocular-inertial (cam0's fisheye undistorted to a pinhole view) at least 60% with an
# ATE under 5 cm.
#   tests/tumvi/check_tumvi.sh PKSLAM WORK
set -euo pipefail
pkslam=$1
work=$2
rm -rf "$work"
mkdir -p "$work"
"$pkslam" --log-level warn simulate --out "$work/render" --camera tumvi --motion medium \
  --duration 16 --quality fast --no-cloud --seed 6 --quiet > "$work/simulate.log"
cp -al "$work/render" "$work/tumvi"
rm "$work/tumvi/mav0/cam0/sensor.yaml" "$work/tumvi/mav0/cam1/sensor.yaml" \
  "$work/tumvi/mav0/imu0/sensor.yaml"
rm -r "$work/tumvi/mav0/state_groundtruth_estimate0" "$work/tumvi/settings.yaml"
"$pkslam" --log-level warn run --dataset "$work/tumvi" --sensor stereo-inertial --out "$work/si" \
  --deterministic --quiet > "$work/si.log"
"$pkslam" eval --gt "$work/tumvi/mav0/mocap0/data.csv" --est "$work/si/trajectory_body.txt" \
  --segments none --json "$work/si.json" > "$work/si.eval"
frames=$(($(wc -l < "$work/tumvi/mav0/cam0/data.csv") - 1))
/usr/bin/python3 - "$work/si.json" "$frames" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
frames = int(sys.argv[2])
print(f"TUM-VI fisheye stereo-inertial: {r['pairs']}/{frames} frames, ATE {r['ate']['rmse']:.4f} m")
sys.exit(0 if r["pairs"] >= 0.95 * frames and r["ate"]["rmse"] < 0.03 else 1)
PY
# Monocular-inertial on the fisheye alone: tracked in cam0's pinhole view (FisheyeUndistortion).
"$pkslam" --log-level warn run --dataset "$work/tumvi" --sensor mono-inertial --out "$work/mi" \
  --deterministic --quiet > "$work/mi.log"
"$pkslam" eval --gt "$work/tumvi/mav0/mocap0/data.csv" --est "$work/mi/trajectory_body.txt" \
  --segments none --json "$work/mi.json" > "$work/mi.eval"
/usr/bin/python3 - "$work/mi.json" "$frames" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
frames = int(sys.argv[2])
print(f"TUM-VI fisheye mono-inertial: {r['pairs']}/{frames} frames, ATE {r['ate']['rmse']:.4f} m")
sys.exit(0 if r["pairs"] >= 0.6 * frames and r["ate"]["rmse"] < 0.05 else 1)
PY
echo "tumvi ok"
