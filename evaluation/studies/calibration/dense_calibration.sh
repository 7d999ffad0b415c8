#!/bin/bash
# Dense accuracy with the file's calibration and with the online estimate (issue 36): the 40 s
# realistic V1_02 replay of evaluation/studies/dense/mesh_vs_cloud.sh (from 5 s, euroc preset,
# with the reference clouds), runs with --calibrate off and online (stereo and stereo-inertial,
# --deterministic), `pkslam dense --mesh` of each (online runs: dense reads the run's
# OUT/calibration/settings.yaml), and cloud-compare against reference_cloud.ply /
# reference_observed.ply, aligned through each run's trajectory. Prints a table.
#
#   evaluation/studies/calibration/dense_calibration.sh PKSLAM OUT_DIR
set -euo pipefail
if [ $# -lt 2 ]; then sed -n '2,9p' "$0"; exit 2; fi
pk=$(realpath "$1"); out=$2
root=$(cd "$(dirname "$0")/../../.." && pwd)
replay="${PKSLAM_SHARED_DATA:-$root/../shared/data}/euroc/groundtruth/V1_02_medium.txt"
mkdir -p "$out"
seq="$out/v102_40s_euroc"
[ -d "$seq/mav0" ] || "$pk" simulate --out "$seq" --trajectory "$replay" --start 5 --duration 40 \
  --realism euroc --quiet > /dev/null
gt="$seq/truth/state_groundtruth_exact.csv"
for sensor in stereo stereo-inertial; do
  for mode in off online; do
    run="$out/run_${sensor}_$mode"
    [ -f "$run/stats.json" ] || "$pk" run --dataset "$seq" --sensor "$sensor" --calibrate "$mode" \
      --deterministic --out "$run" --quiet > /dev/null
    mesh="$out/mesh_${sensor}_$mode"
    [ -f "$mesh.json" ] || "$pk" dense --run "$run" --dataset "$seq" --mesh "$mesh.ply" \
      --json "$mesh.json" --quiet > "$mesh.log"
    [ -f "$out/compare_${sensor}_$mode.json" ] || "$pk" cloud-compare --cloud "$mesh.ply" \
      --ref "$seq/reference_cloud.ply" --observed-ref "$seq/reference_observed.ply" \
      --align-run "$run" --gt "$gt" --json "$out/compare_${sensor}_$mode.json" \
      > "$out/compare_${sensor}_$mode.log"
    # Stereo runs have no body trajectory: the camera's, against the ground truth moved into it.
    if [ "$sensor" = stereo ]; then
      "$pk" eval --gt "$gt" --est "$run/trajectory.txt" \
        --body-from-camera "$run/body_from_camera.txt" > "$out/ate_${sensor}_$mode.txt"
    else
      "$pk" eval --gt "$gt" --est "$run/trajectory_body.txt" > "$out/ate_${sensor}_$mode.txt"
    fi
  done
done
/usr/bin/python3 - "$out" <<'PY'
import json, re, sys
out = sys.argv[1]
print("| sensor | calibration | accuracy mean / median (cm) | within 5 cm | completeness observed 3 m | ATE (cm) |")
print("|---|---|---|---|---|---|")
for sensor in ["stereo", "stereo-inertial"]:
    for mode in ["off", "online"]:
        c = json.load(open(f"{out}/compare_{sensor}_{mode}.json"))
        text = open(f"{out}/ate_{sensor}_{mode}.txt").read()
        m = re.search(r"^ATE \[m\]\s+(\S+)", text, re.M)
        ate = f"{float(m.group(1)) * 100:.2f}" if m else "?"
        acc = c["surface_accuracy"] or c["accuracy"]
        obs = c["completeness_observed"][0]
        print(f"| {sensor} | {mode} | {100 * acc['mean']:.2f} / {100 * acc['median']:.2f} | "
              f"{100 * acc['within']['0.05']:.1f}% | {100 * obs['completeness']:.1f}% | {ate} |")
PY
