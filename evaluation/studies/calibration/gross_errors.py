#!/usr/bin/python3
"""Gross calibration errors written into a render's files (issue 36): copies of SEQ (images,
IMU and ground truth linked, not copied) whose sensor.yaml files carry

  rot2    the camera-IMU rotation 2 deg off (both cameras' T_BS turned about the body's x+y axis)
  td10    cam0's timeshift_cam_imu = -10 ms (Kalibr's convention; the file otherwise says 0)
  focal5  fx and fy of both cameras +5 px

then runs stereo-inertial `pkslam run` with --calibrate off and online on each and prints ATE
(SE(3)), the share of frames tracked, the warnings and the estimate of the parameter the error
was written into, against the truth (SEQ/truth), and the parameters the run's warnings name
(system/calibration_outputs.cc's rule, recomputed from stats.json).

  /usr/bin/python3 evaluation/studies/calibration/gross_errors.py PKSLAM SEQ OUT [--runs N]

SEQ is a render of evaluation/studies/calibration/render.sh (the docs use V2_01_all).
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from calibration_table import warned  # noqa: E402
from calibration_truth import truth_parameters  # noqa: E402

KINDS = {'rot2': ['imu.rx', 'imu.ry', 'imu.rz'], 'td10': ['time_offset'],
         'focal5': ['cam0.fx', 'cam0.fy', 'cam1.fx']}


def rotation(axis, deg):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    t = math.radians(deg)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(t) * k + (1 - math.cos(t)) * k @ k


def truth_for_variant(truth, kind):
    """The truth as the variant's parameters see it: the imu.r* parameters are changes from the
    file's body_from_cam0, and rot2's file is R_gross * the render's file, so the true change
    from it is rotvec(R_true R_file^T R_gross^T)."""
    if kind != 'rot2':
        return truth
    phi = np.radians([truth['imu.rx'], truth['imu.ry'], truth['imu.rz']])
    change = rotation(phi, math.degrees(np.linalg.norm(phi))) if np.linalg.norm(phi) > 0 else np.eye(3)
    m = change @ rotation([1, 1, 0], 2.0).T
    angle = math.acos(max(-1.0, min(1.0, (np.trace(m) - 1) / 2)))
    axis = np.array([m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]]) / (2 * math.sin(angle))
    out = dict(truth)
    for a, v in zip('xyz', np.degrees(angle * axis)):
        out[f'imu.r{a}'] = float(v)
    return out


def make_variant(seq, out, kind):
    """OUT: SEQ with links to its data and edited sensor.yaml files (SEQ is not modified)."""
    if os.path.isfile(f'{out}/mav0/cam0/sensor.yaml'):
        return
    os.makedirs(f'{out}/mav0', exist_ok=True)
    for entry in os.listdir(f'{seq}/mav0'):
        src = os.path.abspath(f'{seq}/mav0/{entry}')
        if entry in ('cam0', 'cam1'):
            os.makedirs(f'{out}/mav0/{entry}', exist_ok=True)
            for name in os.listdir(src):
                if name != 'sensor.yaml':
                    os.symlink(f'{src}/{name}', f'{out}/mav0/{entry}/{name}')
        else:
            os.symlink(src, f'{out}/mav0/{entry}')
    os.symlink(os.path.abspath(f'{seq}/truth'), f'{out}/truth')
    for cam in ('cam0', 'cam1'):
        with open(f'{seq}/mav0/{cam}/sensor.yaml') as f:
            text = f.read()
        if kind == 'rot2':
            m = re.search(r'T_BS:.*?data: \[([^\]]*)\]', text, re.S)
            t = np.array([float(x) for x in m.group(1).replace('\n', ' ').split(',')]).reshape(4, 4)
            r = rotation([1, 1, 0], 2.0)
            t2 = t.copy()
            t2[:3, :3], t2[:3, 3] = r @ t[:3, :3], r @ t[:3, 3]
            text = text[:m.start(1)] + ', '.join(repr(float(x)) for x in t2.ravel()) + text[m.end(1):]
        elif kind == 'focal5':
            m = re.search(r'intrinsics: \[([^\]]*)\]', text)
            v = [float(x) for x in m.group(1).split(',')]
            v[0] += 5
            v[1] += 5
            text = text[:m.start(1)] + ', '.join(repr(x) for x in v) + text[m.end(1):]
        elif kind == 'td10' and cam == 'cam0':
            text = re.sub(r'\ntimeshift_cam_imu:.*', '', text) + 'timeshift_cam_imu: -0.010\n'
        with open(f'{out}/mav0/{cam}/sensor.yaml', 'w') as f:
            f.write(text)


def run(pkslam, seq, out, mode, seed):
    if not os.path.isfile(f'{out}/stats.json'):
        subprocess.run([pkslam, 'run', '--dataset', seq, '--sensor', 'stereo-inertial',
                        '--calibrate', mode, '--seed', str(seed), '--out', out, '--quiet'],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    ev = subprocess.run([pkslam, 'eval', '--gt', f'{seq}/mav0/state_groundtruth_estimate0/data.csv',
                         '--est', f'{out}/trajectory_body.txt'], capture_output=True, text=True)
    m = re.search(r'^ATE \[m\]\s+(\S+)', ev.stdout, re.M)
    with open(f'{out}/stats.json') as f:
        stats = json.load(f)
    frames = stats.get('frames', 0)
    tracked = stats.get('tracking_states', {}).get('OK', 0) / frames if frames else 0.0
    return float(m.group(1)) if m else math.inf, tracked, stats.get('calibration', {})


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('pkslam')
    ap.add_argument('seq')
    ap.add_argument('out')
    ap.add_argument('--runs', type=int, default=1)
    args = ap.parse_args()
    truth = truth_parameters(args.seq)
    print('| error in the file | calibration | seed | ATE (mm) | frames tracked | estimate - truth '
          '(the parameter with the error) | parameters warned |')
    print('|---|---|---|---|---|---|---|')
    for kind, names in KINDS.items():
        seq = os.path.join(args.out, f'seq_{kind}')
        make_variant(args.seq, seq, kind)
        kind_truth = truth_for_variant(truth, kind)
        for mode in ('off', 'online'):
            for seed in range(1, args.runs + 1):
                ate, tracked, cal = run(args.pkslam, seq, os.path.join(args.out, f'{kind}_{mode}_{seed}'),
                                        mode, seed)
                params = {p['name']: p for p in cal.get('parameters', [])}
                est = ', '.join(f'{n} {params[n]["estimate"] - kind_truth[n]:+.3f} (file '
                                f'{params[n]["file"] - kind_truth[n]:+.3f})'
                                for n in names if n in params and n in kind_truth)
                print(f'| {kind} | {mode} | {seed} | {ate * 1e3:.1f} | {100 * tracked:.1f}% | '
                      f'{est} | {", ".join(warned(cal)) if mode == "online" else ""} |')


if __name__ == '__main__':
    main()
