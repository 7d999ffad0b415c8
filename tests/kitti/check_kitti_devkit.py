#!/usr/bin/python3
"""`pkslam eval --kitti` against a literal re-implementation of the KITTI odometry devkit
(evaluate_odometry.cpp: trajectoryDistances, lastFrameFromSegmentLength, calcSequenceErrors with
lengths 100..800 m and a step of 10 frames, rotationError, translationError; the sequence's mean
translation error in % and rotation error in deg/100 m) on a random 1,500-frame drive and a
drifting estimate. CTest kitti.devkit; exits 1 when a number differs by more than 1e-4.

  check_kitti_devkit.py PKSLAM WORK
"""

import json
import math
import os
import subprocess
import sys

import numpy as np
from scipy.spatial.transform import Rotation


def drive(n, rng):
    """A car-like path: about 1 m per frame, slowly turning, with small pitch and roll."""
    poses = []
    yaw, p = 0.0, np.zeros(3)
    for _ in range(n):
        yaw += rng.normal(0, 0.01)
        r = Rotation.from_euler("zyx", [yaw, rng.normal(0, 0.002), rng.normal(0, 0.002)])
        p = p + r.apply([1.0 + rng.normal(0, 0.05), 0, 0])
        m = np.eye(4)
        m[:3, :3] = r.as_matrix()
        m[:3, 3] = p
        poses.append(m)
    return poses


def drifted(truth, rng):
    """The estimate: relative motions with 1% scale error and a small rotation error each."""
    est = [truth[0].copy()]
    for a, b in zip(truth[:-1], truth[1:]):
        d = np.linalg.inv(a) @ b
        d[:3, 3] *= 1.01
        d[:3, :3] = Rotation.from_rotvec(rng.normal(0, 2e-4, 3)).as_matrix() @ d[:3, :3]
        est.append(est[-1] @ d)
    return est


def write_kitti(poses, path):
    with open(path, "w") as f:
        for m in poses:
            f.write(" ".join(f"{v:.12e}" for v in m[:3, :].reshape(-1)) + "\n")


# --- the devkit's algorithm, step by step ---
LENGTHS = [100, 200, 300, 400, 500, 600, 700, 800]


def trajectory_distances(poses):
    dist = [0.0]
    for i in range(1, len(poses)):
        d = poses[i - 1][:3, 3] - poses[i][:3, 3]
        dist.append(dist[i - 1] + math.sqrt(float(d @ d)))
    return dist


def last_frame_from_segment_length(dist, first_frame, length):
    for i in range(first_frame, len(dist)):
        if dist[i] > dist[first_frame] + length:
            return i
    return -1


def rotation_error(e):
    d = 0.5 * (e[0, 0] + e[1, 1] + e[2, 2] - 1.0)
    return math.acos(max(min(d, 1.0), -1.0))


def translation_error(e):
    return math.sqrt(e[0, 3] ** 2 + e[1, 3] ** 2 + e[2, 3] ** 2)


def calc_sequence_errors(gt, result):
    errors = []
    dist = trajectory_distances(gt)
    for first_frame in range(0, len(gt), 10):
        for length in LENGTHS:
            last_frame = last_frame_from_segment_length(dist, first_frame, length)
            if last_frame == -1:
                continue
            delta_gt = np.linalg.inv(gt[first_frame]) @ gt[last_frame]
            delta_result = np.linalg.inv(result[first_frame]) @ result[last_frame]
            e = np.linalg.inv(delta_result) @ delta_gt
            errors.append((rotation_error(e) / length, translation_error(e) / length))
    return errors


def main():
    pkslam, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    rng = np.random.default_rng(11)
    gt = drive(1500, rng)
    est = drifted(gt, rng)
    write_kitti(gt, os.path.join(work, "gt.txt"))
    write_kitti(est, os.path.join(work, "est.txt"))
    with open(os.path.join(work, "times.txt"), "w") as f:
        for i in range(len(gt)):
            f.write(f"{0.1 * i:.6e}\n")
    out = os.path.join(work, "eval.json")
    p = subprocess.run([pkslam, "eval", "--gt", os.path.join(work, "gt.txt"), "--est",
                        os.path.join(work, "est.txt"), "--times", os.path.join(work, "times.txt"),
                        "--kitti", "--align", "none", "--segments", "none", "--json", out],
                       capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"pkslam eval failed: {p.stdout}{p.stderr}")
    with open(out) as f:
        kitti = json.load(f)["kitti"]
    errors = calc_sequence_errors(gt, est)
    t_percent = 100 * sum(t for _, t in errors) / len(errors)
    r_deg = 100 * 180 / math.pi * sum(r for r, _ in errors) / len(errors)
    failures = []
    if kitti["segments"] != len(errors):
        failures.append(f"segments: pkslam {kitti['segments']}, devkit {len(errors)}")
    for name, mine, theirs in (("translation %", kitti["trans_percent"], t_percent),
                               ("rotation deg/100 m", kitti["rot_deg_per_100m"], r_deg)):
        if abs(mine - theirs) > 1e-4:
            failures.append(f"{name}: pkslam {mine:.6f}, devkit {theirs:.6f}")
    print(f"KITTI metric on {len(gt)} frames, {len(errors)} segments: pkslam "
          f"{kitti['trans_percent']:.6f} % / {kitti['rot_deg_per_100m']:.6f} deg/100 m, devkit "
          f"algorithm {t_percent:.6f} % / {r_deg:.6f} deg/100 m")
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
