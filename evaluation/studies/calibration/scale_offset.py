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
"""
import csv
import glob
import os
import sys

import stereo_depth_error as sde

OFFSET_FLOOR_PX = 0.005
SCALE_FLOOR_PCT = 0.03


def read_result(path):
    with open(path, newline='') as f:
        rows = list(csv.DictReader(f))
    return rows[-1] if rows else None


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
        offset, depth_scale = sde.rig_offset_scale(truth, sde.load_rig(cam0, cam1))
        rows.append({'run': os.path.relpath(run, os.path.join(bench, 'runs')),
                     'offset_px': offset, 'depth_scale_pct': depth_scale * 100.0,
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
    print('| run | disparity offset left (px) | depth scale left (%) | map too small, Sim(3) (%) '
          '| ATE SE(3) (mm) |')
    print('|---|---|---|---|---|')
    for r in rows:
        print(f"| {r['run']} | {r['offset_px']:+.4f} | {r['depth_scale_pct']:+.3f} "
              f"| {r['map_small_pct']:+.3f} | {r['ate_mm']:.1f} |")
    agreeing, counted = sign_agreement(rows)
    print(f'\nsame sign: {agreeing} of {counted} runs above the floors '
          f'({OFFSET_FLOOR_PX} px, {SCALE_FLOOR_PCT}%); {len(rows) - counted} below')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
