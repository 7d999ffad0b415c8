#!/usr/bin/env python3
"""How wrong a calibration makes stereo depth: range error against depth, for a realistic replay.

    python3 evaluation/studies/calibration/stereo_depth_error.py SEQ [RUN ...]

SEQ is a `pkslam simulate` folder (SEQ/truth/cam0_sensor.yaml and cam1_sensor.yaml: the
calibration it was rendered with; SEQ/mav0/cam*/sensor.yaml: the calibration its files claim);
each RUN a `pkslam run` or `pkslam calibrate` output folder with RUN/calibration/cam*/sensor.yaml
(the estimate). For the files' calibration and each estimate, points spread over cam0's image at
depths of 1 to 8 m are projected into both cameras with the true calibration and triangulated
again from those pixels with the calibration under test, as stereo depth is (rectified with that
calibration, depth = focal x baseline / disparity). Printed per depth: the median range error
(%), and the disparity offset that error amounts to (px at the rectified focal length; positive:
the measured disparity is larger than that calibration needs for the true depth, so points come
out too near). A constant offset over depth is the stereo rig's column offset (principal points,
rotation about y); a constant range error over depth is its scale (focal length, baseline).
Last the offset and scale fitted over every point: 1/z_est = (1 + s)^-1 / z + offset / (f b).

The estimate's error is what the online calibration leaves of the file's; docs/calibration.md
("Where the remaining error comes from") uses it.
"""
import sys

import cv2
import numpy as np

from calibration_truth import load_yaml, t_bs

DEPTHS_M = [1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0]
GRID = (9, 7)  # points across and down the image, inside a 10% margin
UNDISTORT_CRITERIA = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 200, 1e-14)


def load_sensor(path):
    s = load_yaml(path)
    fx, fy, cx, cy = (float(v) for v in s["intrinsics"])
    w, h = (int(v) for v in s["resolution"])
    return {"K": np.array([[fx, 0, cx], [0, fy, cy], [0, 0, 1.0]]),
            "D": np.array(s["distortion_coefficients"], float), "size": (w, h), "T_BS": t_bs(s)}


def load_rig(cam0_path, cam1_path):
    c0, c1 = load_sensor(cam0_path), load_sensor(cam1_path)
    cam1_from_cam0 = np.linalg.inv(c1["T_BS"]) @ c0["T_BS"]
    return c0, c1, cam1_from_cam0


def project(cam, points):
    """Distorted pixels of points (N x 3, camera frame): pinhole with radial-tangential."""
    pixels, _ = cv2.projectPoints(points.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), cam["K"],
                                  cam["D"])
    return pixels.reshape(-1, 2)


def undistort(cam, pixels, rect, new_k):
    """Pixels through the inverse distortion (iterated to convergence: OpenCV's default five
    iterations leave about 0.01 px), then `rect` and `new_k`."""
    return cv2.undistortPointsIter(pixels.reshape(-1, 1, 2), cam["K"], cam["D"], rect, new_k,
                                   UNDISTORT_CRITERIA).reshape(-1, 2)


def true_points(c0):
    """Points on rays through a grid of cam0's image, at each depth (cam0 frame), and their depth."""
    w, h = c0["size"]
    us = np.linspace(0.1 * w, 0.9 * w, GRID[0])
    vs = np.linspace(0.1 * h, 0.9 * h, GRID[1])
    pix = np.array([[u, v] for v in vs for u in us], float).reshape(-1, 1, 2)
    rays = undistort(c0, pix, np.eye(3), np.eye(3))
    pts, depth = [], []
    for z in DEPTHS_M:
        pts.append(np.column_stack([rays * z, np.full(len(rays), z)]))
        depth.append(np.full(len(rays), z))
    return np.vstack(pts), np.concatenate(depth)


def stereo_depth(rig, pixels0, pixels1):
    """Triangulates pixel pairs as rectified stereo with calibration `rig`: points in its cam0
    frame, the rectified focal length and the baseline."""
    c0, c1, cam1_from_cam0 = rig
    r, t = cam1_from_cam0[:3, :3], cam1_from_cam0[:3, 3]
    r0, r1, p0, p1, _, _, _ = cv2.stereoRectify(c0["K"], c0["D"], c1["K"], c1["D"], c0["size"],
                                                r, t, flags=cv2.CALIB_ZERO_DISPARITY, alpha=0)
    u0 = undistort(c0, pixels0, r0, p0)
    u1 = undistort(c1, pixels1, r1, p1)
    f = p0[0, 0]
    baseline = np.linalg.norm(t)
    disparity = u0[:, 0] - u1[:, 0]
    z = f * baseline / disparity
    rect = np.column_stack([(u0[:, 0] - p0[0, 2]) * z / f, (u0[:, 1] - p0[1, 2]) * z / p0[1, 1], z])
    # r0 maps cam0 to rectified: back with its transpose.
    return rect @ r0, z, f, baseline, disparity


def depth_error(truth_rig, rig):
    """Per point: true range, estimated range, disparity measured and disparity needed."""
    c0t, c1t, t10 = truth_rig
    pts, depth = true_points(c0t)
    pix0 = project(c0t, pts)
    pix1 = project(c1t, (t10[:3, :3] @ pts.T).T + t10[:3, 3])
    est, z_rect, f, b, disparity = stereo_depth(rig, pix0, pix1)
    true_range = np.linalg.norm(pts, axis=1)
    est_range = np.linalg.norm(est, axis=1)
    needed = f * b * est_range / (true_range * z_rect)  # the disparity of the true range
    return depth, true_range, est_range, disparity, needed, f, b


def fit_offset_scale(depth, true_range, est_range, f, b):
    """Least squares of 1/r_est = a / r + offset / (f b): offset in px, scale s = 1/a - 1."""
    a = np.column_stack([1.0 / true_range, np.full(len(true_range), 1.0 / (f * b))])
    (coef_a, offset), *_ = np.linalg.lstsq(a, 1.0 / est_range, rcond=None)
    return offset, 1.0 / coef_a - 1.0


def rig_offset_scale(truth_rig, rig):
    """The disparity offset (px) and depth scale error `rig` leaves against `truth_rig`."""
    depth, true_range, est_range, _, _, f, b = depth_error(truth_rig, rig)
    return fit_offset_scale(depth, true_range, est_range, f, b)


def report(name, truth_rig, rig):
    depth, true_range, est_range, disparity, needed, f, b = depth_error(truth_rig, rig)
    cells = []
    for z in DEPTHS_M:
        m = depth == z
        err = np.median(est_range[m] / true_range[m] - 1.0) * 100.0
        off = np.median(disparity[m] - needed[m])
        cells.append(f"{err:+.3f}% ({off:+.3f})")
    offset, scale = fit_offset_scale(depth, true_range, est_range, f, b)
    print(f"| {name} | " + " | ".join(cells) + f" | {offset:+.4f} px, {scale * 100:+.3f}% |")


def main(argv):
    if len(argv) < 2:
        print(__doc__)
        return 2
    seq, runs = argv[1], argv[2:]
    truth = load_rig(f"{seq}/truth/cam0_sensor.yaml", f"{seq}/truth/cam1_sensor.yaml")
    print("Range error and disparity offset (px) by depth; fitted offset and scale.\n")
    print("| calibration | " + " | ".join(f"{z:g} m" for z in DEPTHS_M) + " | fit |")
    print("|---" * (len(DEPTHS_M) + 2) + "|")
    report("truth", truth, truth)
    report("files", truth, load_rig(f"{seq}/mav0/cam0/sensor.yaml", f"{seq}/mav0/cam1/sensor.yaml"))
    for run in runs:
        report(run, truth,
               load_rig(f"{run}/calibration/cam0/sensor.yaml", f"{run}/calibration/cam1/sensor.yaml"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
