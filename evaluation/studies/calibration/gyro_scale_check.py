#!/usr/bin/env python3
"""Is an IMU axis error what biases online calibration? Correct a replay's IMU by the truth and see.

    python3 evaluation/studies/calibration/gyro_scale_check.py SEQ OUT [--pkslam BIN]
        [--sensor stereo-inertial] [--seed 1]
        [--variants none,gyro,gyro-diagonal,gyro+accel,accel,accel-diagonal] [--true-baseline]
        [-- extra pkslam run arguments]

SEQ is a `pkslam simulate --realism euroc` folder (SEQ/truth/realism_draw.yaml holds the drawn
gyro and accelerometer axis matrices M: the IMU reads M w). For each variant, OUT/VARIANT/ is a
copy of SEQ whose imu0/data.csv has the samples corrected by the truth (the images are
symbolic links, SEQ is not modified):
  none            the samples as recorded
  gyro            gyro samples multiplied by M_g^-1 (scale and misalignment removed)
  gyro-diagonal   gyro samples divided by diag(M_g) (the per-axis scale factor only)
  gyro+accel      gyro by M_g^-1 and accelerometer by M_a^-1
  accel           accelerometer samples by M_a^-1 only
  accel-diagonal  accelerometer samples divided by diag(M_a) (its per-axis scale factor only)
then `pkslam run --calibrate online` on it, and prints the ATE (SE(3) alignment), the scale a
Sim(3) alignment finds (the map's scale error), the calibration estimates against the truth
(calibration_truth.py) and the stereo depth error the estimate leaves (stereo_depth_error.py:
the disparity offset and scale fitted over 1-8 m). The biases, g-sensitivity and noise stay.
--true-baseline also puts the stereo translation of the copies' files at the truth (cam1's
T_BS moved so that cam0_from_cam1 has the true translation and the file's rotation): online
calibration holds the baseline at the file's value, so this shows what its error costs. With
--calibrate-hold-gyro-scale among the extra arguments this is the experiment that found the gyro
scale behind cam0's fy bias (docs/calibration.md, "The gyro's scale factor").
"""
import argparse
import json
import os
import shutil
import subprocess
import sys

import numpy as np
import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
sys.path.insert(0, HERE)
import calibration_truth  # noqa: E402
import residual_sources  # noqa: E402
import stereo_depth_error  # noqa: E402

VARIANTS = ("none", "gyro", "gyro-diagonal", "gyro+accel", "accel", "accel-diagonal")


def corrected_copy(seq, out, variant, draw):
    """OUT: SEQ with links to everything but imu0/data.csv, which is rewritten."""
    os.makedirs(os.path.join(out, "mav0", "imu0"), exist_ok=True)
    for name in os.listdir(seq):
        if name != "mav0" and not os.path.exists(os.path.join(out, name)):
            os.symlink(os.path.abspath(os.path.join(seq, name)), os.path.join(out, name))
    for name in os.listdir(os.path.join(seq, "mav0")):
        target = os.path.join(out, "mav0", name)
        if name != "imu0" and not os.path.exists(target):
            os.symlink(os.path.abspath(os.path.join(seq, "mav0", name)), target)
    shutil.copy(os.path.join(seq, "mav0", "imu0", "sensor.yaml"),
                os.path.join(out, "mav0", "imu0", "sensor.yaml"))
    mg = np.array(draw["imu_gyro_matrix"], float)
    ma = np.array(draw["imu_accel_matrix"], float)
    # The variants are checked in main(); the ones not named here leave that sensor as recorded.
    gyro_fix = {"gyro": np.linalg.inv(mg), "gyro-diagonal": np.diag(1.0 / np.diag(mg)),
                "gyro+accel": np.linalg.inv(mg)}.get(variant, np.eye(3))
    accel_fix = {"gyro+accel": np.linalg.inv(ma), "accel": np.linalg.inv(ma),
                 "accel-diagonal": np.diag(1.0 / np.diag(ma))}.get(variant, np.eye(3))
    with open(os.path.join(seq, "mav0", "imu0", "data.csv")) as f:
        lines = f.read().splitlines()
    rows = [lines[0]]
    for line in lines[1:]:
        v = line.split(",")
        g = gyro_fix @ np.array(v[1:4], float)
        a = accel_fix @ np.array(v[4:7], float)
        rows.append(",".join([v[0]] + [repr(float(x)) for x in g] + [repr(float(x)) for x in a]))
    with open(os.path.join(out, "mav0", "imu0", "data.csv"), "w") as f:
        f.write("\n".join(rows) + "\n")


def true_baseline_files(seq, out):
    """OUT/mav0/cam1: SEQ's cam1 with the images linked and sensor.yaml's T_BS moved so that
    cam0_from_cam1 keeps the file's rotation and takes the truth's translation."""
    cam1 = os.path.join(out, "mav0", "cam1")
    if os.path.islink(cam1):
        os.unlink(cam1)
    os.makedirs(cam1, exist_ok=True)
    for name in os.listdir(os.path.join(seq, "mav0", "cam1")):
        if name != "sensor.yaml" and not os.path.exists(os.path.join(cam1, name)):
            os.symlink(os.path.abspath(os.path.join(seq, "mav0", "cam1", name)),
                       os.path.join(cam1, name))

    def body_from(path):
        return calibration_truth.t_bs(calibration_truth.load_yaml(os.path.join(seq, path)))
    file0 = body_from("mav0/cam0/sensor.yaml")
    cam0_from_cam1 = np.linalg.inv(file0) @ body_from("mav0/cam1/sensor.yaml")
    true_cam0_from_cam1 = (np.linalg.inv(body_from("truth/cam0_sensor.yaml"))
                           @ body_from("truth/cam1_sensor.yaml"))
    cam0_from_cam1[:3, 3] = true_cam0_from_cam1[:3, 3]
    with open(os.path.join(seq, "mav0", "cam1", "sensor.yaml")) as f:
        text = residual_sources.with_tbs(f.read(), file0 @ cam0_from_cam1)
    with open(os.path.join(cam1, "sensor.yaml"), "w") as f:
        f.write(text)


def ate(pkslam, seq, run, align="se3"):
    """ATE rmse (m) and the alignment's scale."""
    out = os.path.join(run, f"ate_{align}.json")
    subprocess.run([pkslam, "eval", "--gt",
                    os.path.join(seq, "mav0", "state_groundtruth_estimate0", "data.csv"),
                    "--est", os.path.join(run, "trajectory_body.txt"), "--align", align,
                    "--segments", "none", "--json", out], capture_output=True, check=True)
    with open(out) as f:
        result = json.load(f)
    return result["ate"]["rmse"], result["scale"]


def main():
    argv = sys.argv[1:]
    extra = []
    if "--" in argv:
        extra = argv[argv.index("--") + 1:]
        argv = argv[:argv.index("--")]
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("seq")
    ap.add_argument("out")
    ap.add_argument("--pkslam", default=os.path.join(REPO, "build", "bin", "pkslam"))
    ap.add_argument("--sensor", default="stereo-inertial")
    ap.add_argument("--seed", default="1")
    ap.add_argument("--variants", default=",".join(VARIANTS))
    ap.add_argument("--true-baseline", action="store_true",
                    help="the copies' files hold the true stereo translation")
    args = ap.parse_args(argv)
    variants = args.variants.split(",")
    for v in variants:
        if v not in VARIANTS:
            ap.error(f"unknown variant {v!r} (one of {', '.join(VARIANTS)})")
    with open(os.path.join(args.seq, "truth", "realism_draw.yaml")) as f:
        draw = yaml.safe_load(f.read().replace("%YAML:1.0", ""))
    if "imu_gyro_matrix" not in draw:
        sys.exit(f"{args.seq}/truth/realism_draw.yaml: no imu_gyro_matrix (not a euroc-preset render)")
    truth = calibration_truth.truth_parameters(args.seq)
    print(f"{'variant':15s} {'ATE [mm]':>9s} {'Sim3 scale-1 %':>14s} {'fx-truth':>9s} "
          f"{'fy-truth':>9s} {'td-truth ms':>11s} {'gyro sy-truth %':>15s} "
          f"{'stereo offset px':>16s} {'stereo scale %':>14s}")
    truth_rig = stereo_depth_error.load_rig(os.path.join(args.seq, "truth", "cam0_sensor.yaml"),
                                            os.path.join(args.seq, "truth", "cam1_sensor.yaml"))
    for v in variants:
        folder = os.path.join(args.out, v)
        corrected_copy(args.seq, os.path.join(folder, "seq"), v, draw)
        if args.true_baseline:
            true_baseline_files(args.seq, os.path.join(folder, "seq"))
        run = os.path.join(folder, "run")
        with open(os.path.join(folder, "run.log"), "w") as log:
            subprocess.run([args.pkslam, "run", "--dataset", os.path.join(folder, "seq"),
                            "--sensor", args.sensor, "--calibrate", "online", "--seed", args.seed,
                            "--out", run, "--quiet"] + extra, stdout=log, stderr=log, check=True)
        est = calibration_truth.run_parameters(run)

        def err(name):
            return est[name]["estimate"] - truth[name] if name in est else float("nan")
        # A corrected IMU has no scale error left: the truth of the gyro's scale is then 0.
        gyro_truth = 0.0 if v.startswith("gyro") else truth.get("gyro.sy", 0.0)
        gyro = est["gyro.sy"]["estimate"] - gyro_truth if "gyro.sy" in est else float("nan")
        se3, _ = ate(args.pkslam, args.seq, run)
        _, scale = ate(args.pkslam, args.seq, run, "sim3")
        offset, depth_scale = stereo_depth_error.rig_offset_scale(
            truth_rig, stereo_depth_error.load_rig(
                os.path.join(run, "calibration", "cam0", "sensor.yaml"),
                os.path.join(run, "calibration", "cam1", "sensor.yaml")))
        print(f"{v:15s} {se3 * 1e3:9.2f} {(scale - 1) * 100:14.3f} {err('cam0.fx'):9.3f} "
              f"{err('cam0.fy'):9.3f} {err('time_offset'):11.3f} {gyro:15.3f} "
              f"{offset:16.4f} {depth_scale * 100:14.3f}", flush=True)


if __name__ == "__main__":
    main()
