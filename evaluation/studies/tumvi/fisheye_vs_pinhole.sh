#!/usr/bin/env bash
# TUM-VI's fisheye against EuRoC's pinhole on the same flight (docs/run.md, "TUM-VI"): renders one
# random medium flight twice (`simulate --camera tumvi` and `--camera euroc`), removes the tumvi
# render's sensor.yaml files and EuRoC ground truth so it is read as a TUM-VI folder (dso/
# camchain, mocap0), runs every sensor mode on both (--deterministic, one run each) and prints
# frames in the trajectory and ATE (SE(3); monocular Sim(3)).
#   evaluation/studies/tumvi/fisheye_vs_pinhole.sh OUT [PKSLAM]
set -euo pipefail
out=$1
pkslam=${2:-"$(dirname "$0")/../../../build/bin/pkslam"}
mkdir -p "$out"
for cam in tumvi euroc; do
  [ -d "$out/render_$cam" ] || "$pkslam" --log-level warn simulate --out "$out/render_$cam" \
    --camera "$cam" --motion medium --duration 25 --quality fast --no-cloud --seed 6 --quiet \
    > /dev/null
done
if [ ! -d "$out/tumvi" ]; then
  cp -al "$out/render_tumvi" "$out/tumvi"
  rm "$out"/tumvi/mav0/cam{0,1}/sensor.yaml "$out/tumvi/mav0/imu0/sensor.yaml"
  rm -r "$out/tumvi/mav0/state_groundtruth_estimate0" "$out/tumvi/settings.yaml"
fi
printf '%-8s %-16s %8s %9s\n' camera sensor frames "ATE [mm]"
for d in tumvi render_euroc; do
  gt="$out/$d/mav0/state_groundtruth_estimate0/data.csv"
  [ -f "$gt" ] || gt="$out/$d/mav0/mocap0/data.csv"
  frames=$(($(wc -l < "$out/$d/mav0/cam0/data.csv") - 1))
  for s in stereo-inertial mono-inertial stereo mono; do
    run="$out/run_${d}_$s"
    "$pkslam" --log-level warn run --dataset "$out/$d" --sensor "$s" --out "$run" \
      --deterministic --quiet > /dev/null
    if [ "$s" = mono ]; then
      "$pkslam" eval --gt "$gt" --est "$run/trajectory.txt" \
        --body-from-camera "$run/body_from_camera.txt" --align sim3 --segments none \
        --json "$run/ate.json" > /dev/null
    else
      "$pkslam" eval --gt "$gt" --est "$run/trajectory_body.txt" --segments none \
        --json "$run/ate.json" > /dev/null
    fi
    /usr/bin/python3 -c "
import json, sys
r = json.load(open(sys.argv[1]))
print('%-8s %-16s %4d/%-4d %8.1f' % (sys.argv[2], sys.argv[3], r['pairs'], int(sys.argv[4]), 1e3 * r['ate']['rmse']))
" "$run/ate.json" "${d#render_}" "$s" "$frames"
  done
done
