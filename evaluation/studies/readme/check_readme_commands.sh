#!/bin/bash
# Runs every command of the README's subcommand table, in order, as a new user would after
# `scripts/demo` or `scripts/build` on a fresh clone (P = build/bin/pkslam of REPO, run from a
# scratch folder, ../shared beside REPO). Prints each command with its exit code; exits 1 if any
# failed. The Quick start scripts themselves are run by the caller (scripts/demo, scripts/test).
#
#   evaluation/studies/readme/check_readme_commands.sh REPO WORK_DIR
set -uo pipefail
if [ $# -ne 2 ]; then sed -n '2,8p' "$0"; exit 2; fi
repo=$(realpath "$1"); work=$2
mkdir -p "$work" && cd "$work" || exit 2
P="$repo/build/bin/pkslam"
ln -sfn "$repo/../shared" ../shared 2>/dev/null || true
ln -sfn "$repo/evaluation" evaluation
ln -sfn "$repo/Vocabulary" Vocabulary
status=0
run() {
  echo "\$ $*"
  if ! eval "$@" > cmd.log 2>&1; then
    echo "  FAILED (exit $?): $(tail -1 cmd.log)"; status=1
  else
    echo "  ok: $(tail -1 cmd.log | cut -c1-150)"
  fi
}
# The table's examples, in the table's order (simulate first: the others use its outputs).
run "$P simulate --trajectory ../shared/data/euroc/groundtruth/V1_02_medium.txt --duration 20 --out seq --quiet"
run "$P run --dataset seq --sensor stereo-inertial --selector pks --trace --out run --quiet"
run "$P eval --gt seq/mav0/state_groundtruth_estimate0/data.csv --est run/trajectory_body.txt"
run "$P view --run run --dataset seq"
run "$P info seq"
run "$P run --dataset seq --sensor stereo-inertial --out run_map --save-map run.map --quiet && $P map info run.map"
run "$P bench bench/suites/smoke.yaml --out bench --quiet"
run "$P dense --run run --dataset seq --out cloud.ply --mesh mesh.ply --quiet"
run "$P cloud-compare --cloud mesh.ply --ref seq/reference_cloud.ply --align-run run --gt seq/mav0/state_groundtruth_estimate0/data.csv"
run "$P export-colmap --run run --dataset seq --out colmap"
run "$P tracks simulate --out t --noise 1 && $P tracks reconstruct t --out r"
run "$P vocab info Vocabulary/pkslam_orb_k10_L6.bin"
run "$P simulate --rgbd --duration 5 --out rgbd_seq --quiet && $P rgbd-odometry --dataset rgbd_seq --out odo"
exit $status
