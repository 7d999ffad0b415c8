#!/usr/bin/python3
"""One stereo-inertial `--calibrate online` run per render of the calibration study (render.sh's
`_all` and `_calibration_off` renders of the five replays), two at a time, and the issue's ratios
against the study's `off` medians (docs/calibration.md, "Stereo-inertial again": `off` changes
only with commits that move every run), with the estimates against the truth. A quick look at a
new build between studies, not a study: one run per cell.

    /usr/bin/python3 evaluation/studies/calibration/quick_check.py RENDERS OUT [--pkslam BIN]
"""
import argparse
import json
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from calibration_truth import truth_parameters  # noqa: E402

# `off` on the true-calibration render, median of 3 (docs/calibration.md, "Stereo-inertial
# again", the build of d18215d; the first study's, commit 43cb76e, were 6.7, 9.7, 4.6, 5.1, 4.0).
OFF_TRUE = {'MH_01': 0.00413, 'MH_02': 0.00475, 'V1_01': 0.00416, 'V1_02': 0.00464, 'V2_01': 0.00417}
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))


def run(pkslam, renders, out, render):
    run_dir = os.path.join(out, render)
    if not os.path.exists(os.path.join(run_dir, 'stats.json')):
        with open(run_dir + '.log', 'w') as log:
            subprocess.run([pkslam, 'run', '--dataset', os.path.join(renders, render), '--sensor',
                            'stereo-inertial', '--calibrate', 'online', '--out', run_dir,
                            '--quiet'], stdout=log, stderr=subprocess.STDOUT, check=True)
    gt = os.path.join(renders, render, 'mav0/state_groundtruth_estimate0/data.csv')
    subprocess.run([pkslam, 'eval', '--gt', gt, '--est', os.path.join(run_dir, 'trajectory_body.txt'),
                    '--segments', 'none', '--json', os.path.join(run_dir, 'ate.json')],
                   capture_output=True, check=True)
    ate = json.load(open(os.path.join(run_dir, 'ate.json')))['ate']['rmse']
    calibration = json.load(open(os.path.join(run_dir, 'stats.json')))['calibration']
    truth = truth_parameters(os.path.join(renders, render))
    estimate = {p['name']: p['estimate'] for p in calibration['parameters']}

    def worst(names):
        return max(abs(estimate[n] - truth[n]) for n in names if n in truth)
    return ate, calibration['covariance'], (worst(['imu.rx', 'imu.ry', 'imu.rz']),
                                            worst(['stereo.rx', 'stereo.ry', 'stereo.rz']),
                                            worst(['cam0.fx', 'cam0.fy', 'cam1.fx']))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('renders')
    ap.add_argument('out')
    ap.add_argument('--pkslam', default=os.path.join(REPO, 'build', 'bin', 'pkslam'))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    renders = [f'{s}_{k}' for s in OFF_TRUE for k in ('all', 'calibration_off')]
    with ThreadPoolExecutor(max_workers=2) as pool:
        results = dict(zip(renders, pool.map(lambda r: run(a.pkslam, a.renders, a.out, r), renders)))
    print('| trajectory | online, file cal. | online, true cal. | recovery (<= 1.3) | no harm (<= 1.05) '
          '| covariance (file / true cal.) | camera-IMU rotation (deg) | stereo rotation (deg) | focal (px) |')
    print('|---|---|---|---|---|---|---|---|---|')
    for seq, off in OFF_TRUE.items():
        ate_all, cov_all, err = results[f'{seq}_all']
        ate_true, cov_true, _ = results[f'{seq}_calibration_off']
        print(f'| {seq} | {ate_all * 1e3:.1f} mm | {ate_true * 1e3:.1f} mm | {ate_all / off:.2f} | '
              f'{ate_true / off:.2f} | {cov_all} / {cov_true} | {err[0]:.3f} | {err[1]:.3f} | {err[2]:.2f} |')


if __name__ == '__main__':
    main()
