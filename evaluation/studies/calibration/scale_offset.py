#!/usr/bin/env python3
"""Is the map's scale error the stereo rig's disparity offset? Per stereo run of a calibration
bench: the disparity offset and depth scale its calibration (OUT/calibration/: the online
estimate, or the files' values for `off`) leaves against the render's truth (stereo_depth_error.py's
fit over 1-8 m), beside the scale a Sim(3) alignment applies to its trajectory.

    python3 evaluation/studies/calibration/scale_offset.py BENCH RENDERS

BENCH is a bench of bench/suites/calibration.yaml (BENCH/runs/DATASET/SENSOR/CONFIG/seedN/ with
result.csv and calibration/cam*/sensor.yaml), RENDERS the folder of render.sh's renders
(RENDERS/DATASET/truth/). A positive offset makes stereo points come out too near, so the map
is too small and the Sim(3) alignment scales it up (sim3_scale > 1). The last line counts the
runs whose offset and trajectory scale error have the same sign, among those where both are
larger than their noise floor (0.005 px, 0.03%).

When the run's stats.json holds the estimate's joint covariance (`calibration.covariance_matrix`,
since 2026-12-03), the offset's posterior sigma comes beside it: the offset's derivatives by
each camera-side parameter (numerical, through the same fit) against that covariance. The offset
left divided by its sigma says whether the estimate's error is what its data allow (about 1) or a
bias the model does not know of (several).
"""
import copy
import csv
import glob
import json
import os
import sys

import cv2
import numpy as np

import stereo_depth_error as sde

OFFSET_FLOOR_PX = 0.005
SCALE_FLOOR_PCT = 0.03


def read_result(path):
    with open(path, newline='') as f:
        rows = list(csv.DictReader(f))
    return rows[-1] if rows else None


# Central-difference steps of the camera-side parameters (report units: px, "", deg, mm).
STEPS = {'px': 0.05, '': 1e-4, 'deg': 1e-3, 'mm': 0.05}


def perturbed(rig, name, delta):
    """`rig` (stereo_depth_error's (cam0, cam1, cam1_from_cam0)) with the reported parameter
    `name` moved by `delta`, as the estimator moves it: cam1's fy and cy follow cam0's; stereo.r*
    turn cam0_from_cam1 by the rotation vector (deg, cam0 axes) on the left, stereo.t* shift its
    translation (mm, cam0 axes). None for parameters stereo depth does not depend on."""
    c0, c1, cam1_from_cam0 = copy.deepcopy(rig)
    cam, _, field = name.partition('.')
    k_index = {'fx': (0, 0), 'fy': (1, 1), 'cx': (0, 2), 'cy': (1, 2)}
    if cam in ('cam0', 'cam1') and field in k_index:
        c = c0 if cam == 'cam0' else c1
        c['K'][k_index[field]] += delta
        if cam == 'cam0' and field in ('fy', 'cy'):
            c1['K'][k_index[field]] += delta
    elif cam in ('cam0', 'cam1') and field in ('k1', 'k2'):
        (c0 if cam == 'cam0' else c1)['D'][int(field[1]) - 1] += delta
    elif cam == 'stereo' and field in ('rx', 'ry', 'rz', 'tx', 'ty', 'tz'):
        cam0_from_cam1 = np.linalg.inv(cam1_from_cam0)
        axis = 'xyz'.index(field[1])
        if field[0] == 'r':
            v = np.zeros(3)
            v[axis] = np.radians(delta)
            cam0_from_cam1[:3, :3] = cv2.Rodrigues(v)[0] @ cam0_from_cam1[:3, :3]
        else:
            cam0_from_cam1[axis, 3] += delta * 1e-3
        cam1_from_cam0 = np.linalg.inv(cam0_from_cam1)
    else:
        return None
    return c0, c1, cam1_from_cam0


def offset_sigma(truth, rig, stats):
    """The posterior sigma (px) of the disparity offset `rig` leaves against `truth`, from the
    joint covariance in `stats` (a stats.json dict); None without one."""
    matrix = (stats.get('calibration') or {}).get('covariance_matrix') or {}
    names = matrix.get('names') or []
    if not names:
        return None
    units = {p['name']: p['unit'] for p in stats['calibration']['parameters']}
    gradient = np.zeros(len(names))
    for i, name in enumerate(names):
        step = STEPS.get(units.get(name, ''), 1e-4)
        plus, minus = perturbed(rig, name, step), perturbed(rig, name, -step)
        if plus is None:
            continue
        gradient[i] = (sde.rig_offset_scale(truth, plus)[0] -
                       sde.rig_offset_scale(truth, minus)[0]) / (2 * step)
    covariance = np.asarray(matrix['matrix'], float)
    return float(np.sqrt(max(0.0, gradient @ covariance @ gradient)))


def read_stats(run):
    path = os.path.join(run, 'stats.json')
    if not os.path.isfile(path):
        return {}
    with open(path) as f:
        return json.load(f)


def run_rows(bench, renders):
    """One dict per finished stereo run with OUT/calibration/, sorted by run id."""
    rows = []
    pattern = os.path.join(bench, 'runs', '*', '*', '*', 'seed*', 'result.csv')
    for result_path in sorted(glob.glob(pattern)):
        run = os.path.dirname(result_path)
        cam0 = os.path.join(run, 'calibration', 'cam0', 'sensor.yaml')
        cam1 = os.path.join(run, 'calibration', 'cam1', 'sensor.yaml')
        if not (os.path.isfile(cam0) and os.path.isfile(cam1)):
            continue  # monocular runs write no cam1
        result = read_result(result_path)
        if result is None or result.get('status') != 'ok' or not result.get('sim3_scale'):
            continue
        dataset = result['dataset']
        truth_dir = os.path.join(renders, dataset, 'truth')
        truth = sde.load_rig(os.path.join(truth_dir, 'cam0_sensor.yaml'),
                             os.path.join(truth_dir, 'cam1_sensor.yaml'))
        rig = sde.load_rig(cam0, cam1)
        offset, depth_scale = sde.rig_offset_scale(truth, rig)
        rows.append({'run': os.path.relpath(run, os.path.join(bench, 'runs')),
                     'offset_px': offset, 'depth_scale_pct': depth_scale * 100.0,
                     'offset_sigma_px': offset_sigma(truth, rig, read_stats(run)),
                     'map_small_pct': (float(result['sim3_scale']) - 1.0) * 100.0,
                     'ate_mm': float(result['ate_m']) * 1000.0})
    return rows


def sign_agreement(rows):
    """(agreeing, counted): runs whose offset and map scale error share a sign, above the floors."""
    counted = [r for r in rows
               if abs(r['offset_px']) > OFFSET_FLOOR_PX and abs(r['map_small_pct']) > SCALE_FLOOR_PCT]
    agreeing = [r for r in counted if (r['offset_px'] > 0) == (r['map_small_pct'] > 0)]
    return len(agreeing), len(counted)


def main(argv):
    if len(argv) != 3:
        print(__doc__)
        return 2
    rows = run_rows(argv[1], argv[2])
    if not rows:
        print(f'{argv[1]}: no finished stereo run with OUT/calibration/', file=sys.stderr)
        return 1
    print('| run | disparity offset left (px) | its sigma (px) | depth scale left (%) '
          '| map too small, Sim(3) (%) | ATE SE(3) (mm) |')
    print('|---|---|---|---|---|---|')
    for r in rows:
        sigma = r['offset_sigma_px']
        sigma_cell = '' if sigma is None else f"{sigma:.4f} ({r['offset_px'] / sigma:+.1f} sigma)"
        print(f"| {r['run']} | {r['offset_px']:+.4f} | {sigma_cell} | {r['depth_scale_pct']:+.3f} "
              f"| {r['map_small_pct']:+.3f} | {r['ate_mm']:.1f} |")
    agreeing, counted = sign_agreement(rows)
    print(f'\nsame sign: {agreeing} of {counted} runs above the floors '
          f'({OFFSET_FLOOR_PX} px, {SCALE_FLOOR_PCT}%); {len(rows) - counted} below')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
