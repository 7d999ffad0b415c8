#!/usr/bin/env python3
"""Estimate minus truth per calibration parameter, for a run of a realistic replay.

    python3 evaluation/studies/calibration/calibration_truth.py RUN SEQ [RUN2 ...]

RUN is a `pkslam run` / `pkslam calibrate` output folder (its stats.json "calibration" section),
SEQ the `pkslam simulate` folder it ran on: SEQ/truth/ holds the rendering calibration and
SEQ/truth/realism_draw.yaml the errors written into the sequence's files. The parameters are
those of docs/calibration.md (intrinsics in px; the changes of body_from_cam0 and cam0_from_cam1
from the file as rotation vector in deg and translation in mm; time offset in ms; the gyro's
per-axis scale-factor error in %). Prints, per parameter: file - truth,
estimate - truth, the estimate's sigma, and whether it was freed. With several runs, the median
over them of |estimate - truth|.
"""
import json
import math
import sys

import numpy as np
import yaml


def exp_se3(xi):
    """SE(3) exp of [rho; phi] (pkslam's tangent order) as a 4x4 matrix."""
    rho, phi = np.asarray(xi[:3], float), np.asarray(xi[3:], float)
    th = np.linalg.norm(phi)
    k = np.array([[0, -phi[2], phi[1]], [phi[2], 0, -phi[0]], [-phi[1], phi[0], 0]])
    if th < 1e-12:
        r, v = np.eye(3) + k, np.eye(3) + 0.5 * k
    else:
        r = np.eye(3) + math.sin(th) / th * k + (1 - math.cos(th)) / th**2 * k @ k
        v = np.eye(3) + (1 - math.cos(th)) / th**2 * k + (th - math.sin(th)) / th**3 * k @ k
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = r, v @ rho
    return m


def log_se3(m):
    r, t = m[:3, :3], m[:3, 3]
    c = max(-1.0, min(1.0, (np.trace(r) - 1) / 2))
    th = math.acos(c)
    if th < 1e-12:
        phi = 0.5 * np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    else:
        phi = th / (2 * math.sin(th)) * np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    k = np.array([[0, -phi[2], phi[1]], [phi[2], 0, -phi[0]], [-phi[1], phi[0], 0]])
    if th < 1e-12:
        v = np.eye(3) + 0.5 * k
    else:
        v = np.eye(3) + (1 - math.cos(th)) / th**2 * k + (th - math.sin(th)) / th**3 * k @ k
    return np.concatenate([np.linalg.solve(v, t), phi])


def load_yaml_text(text):
    """A sensor.yaml's text (OpenCV's "%YAML:1.0" directive dropped) as a dict."""
    return yaml.safe_load("".join(l for l in text.splitlines(True) if not l.startswith("%")))


def load_yaml(path):
    with open(path) as f:
        return load_yaml_text(f.read())


def t_bs(sensor):
    d = sensor["T_BS"]["data"]
    return np.array(d, float).reshape(4, 4)


def truth_parameters(seq):
    """The truth expressed as estimates would be (names of stats.json's calibration section)."""
    out = {}
    cams = []
    for i, name in enumerate(["cam0", "cam1"]):
        try:
            s = load_yaml(f"{seq}/truth/{name}_sensor.yaml")
        except FileNotFoundError:
            continue
        fx, fy, cx, cy = s["intrinsics"]
        k = s["distortion_coefficients"]
        for key, v in zip(["fx", "fy", "cx", "cy", "k1", "k2"], [fx, fy, cx, cy, k[0], k[1]]):
            out[f"{name}.{key}"] = float(v)
        cams.append(t_bs(s))
    draw = load_yaml(f"{seq}/truth/realism_draw.yaml")
    # The files hold body_from_cam0 = Exp(rig_error) * true and cam0_from_cam1 (of the written
    # T_BS) = true * Exp(stereo_error) for cam1_from_cam0; the parameters are the changes of
    # body_from_cam0 and cam0_from_cam1 from the file (docs/calibration.md): rotation vector of
    # R_x R_file^T (deg), translation t_x - t_file (mm).
    rig_error = np.array(draw.get("rig_error", [0] * 6), float)
    stereo_error = np.array(draw.get("stereo_error", [0] * 6), float)

    def change(prefix, true, file):
        rot = log_se3(np.block([[true[:3, :3] @ file[:3, :3].T, np.zeros((3, 1))],
                                [np.zeros((1, 3)), np.ones((1, 1))]]))[3:]
        for i, a in enumerate("xyz"):
            out[f"{prefix}.r{a}"] = math.degrees(rot[i])
            out[f"{prefix}.t{a}"] = (true[i, 3] - file[i, 3]) * 1e3

    t_bc0 = cams[0]
    change("imu", t_bc0, exp_se3(rig_error) @ t_bc0)
    if len(cams) > 1:
        t_c1c0 = np.linalg.inv(cams[1]) @ cams[0]
        t_c1c0_file = t_c1c0 @ exp_se3(stereo_error)
        change("stereo", np.linalg.inv(t_c1c0), np.linalg.inv(t_c1c0_file))
    out["time_offset"] = float(draw.get("camera_imu_offset_ms", 0.0))
    # The gyro reads M w (+ bias, g-sensitivity, noise): its per-axis scale-factor error is
    # diag(M) - 1, in % (the off-diagonal misalignment is not estimated).
    if "imu_gyro_matrix" in draw:
        m = np.array(draw["imu_gyro_matrix"], float)
        for i, a in enumerate("xyz"):
            out[f"gyro.s{a}"] = (m[i, i] - 1.0) * 100.0
    # The accelerometer reads M a: its axis errors E = M - I, the diagonal in %, the
    # misalignment (off the diagonal, small angles) in deg, as stats.json's accel.* entries.
    if "imu_accel_matrix" in draw:
        e = np.array(draw["imu_accel_matrix"], float) - np.eye(3)
        for i, a in enumerate("xyz"):
            for j, b in enumerate("xyz"):
                if i == j:
                    out[f"accel.s{a}"] = e[i, i] * 100.0
                else:
                    out[f"accel.m{a}{b}"] = math.degrees(e[i, j])
    return out


def run_parameters(run):
    with open(f"{run}/stats.json") as f:
        stats = json.load(f)
    return {p["name"]: p for p in stats["calibration"]["parameters"]}


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    runs, seq = argv[1:-1], argv[-1]
    truth = truth_parameters(seq)
    per_run = [run_parameters(r) for r in runs]
    names = [n for n in per_run[0] if n in truth]
    print(f"{'parameter':16s} {'file-truth':>11s} {'est-truth':>11s} {'sigma':>9s} {'|est-truth|/sigma':>17s} freed")
    for n in names:
        p = per_run[0][n]
        ft = p["file"] - truth[n]
        errs = [abs(r[n]["estimate"] - truth[n]) for r in per_run]
        et = p["estimate"] - truth[n] if len(per_run) == 1 else float(np.median(errs))
        sig = p.get("sigma", 0.0)
        ratio = f"{abs(et) / sig:17.2f}" if sig > 0 else f"{'-':>17s}"
        print(f"{n:16s} {ft:11.4f} {et:11.4f} {sig:9.4f} {ratio} {'yes' if p.get('free') else 'no'}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
