#!/usr/bin/python3
"""Where the ATE an online-calibrated run still loses comes from: its estimate fed back as the
calibration files, with one part of it at a time replaced by the render's truth.

    /usr/bin/python3 evaluation/studies/calibration/residual_sources.py RENDER RUN OUT \
        [--pkslam BIN] [--seeds 1,2] [--variants est,true,...]

RENDER is a render of evaluation/studies/calibration/render.sh (its truth/ holds the rendering
calibration and the errors drawn), RUN a stereo-inertial `pkslam run --calibrate online` of it
(RUN/calibration/ holds the estimate as EuRoC sensor.yaml files). For each variant the script
writes OUT/VARIANT/ (a dataset whose images, IMU samples and ground truth link to RENDER's; only
the three sensor.yaml files differ), runs `pkslam run --calibrate off` on it, once per seed, two
at a time, and prints the ATE table. RENDER and RUN are only read.

Variants (each starts from the estimate):
  est        the estimate as it is
  true       every part at the truth (intrinsics, both extrinsics, time offset, gyro scale)
  cam0       cam0's intrinsics and distortion at the truth
  cam1       cam1's intrinsics and distortion at the truth
  stereo     the stereo extrinsic (cam0_from_cam1) at the truth
  imu_rot    the camera-IMU rotation at the truth (the stereo extrinsic kept)
  lever      the camera-IMU translation at the truth
  time_gyro  the time offset and the gyro's per-axis scale factors at the truth
  camera     cam0, cam1 and stereo together
  imu        imu_rot, lever and time_gyro together
  rows       the rectified rows of the two cameras aligned as the truth's: the stereo rotation
             about the baseline (x) at the truth, and cam1's fy and cy at the truth plus cam0's
             estimate's error (the estimate holds these three at the file's values: the
             stereo matcher does not measure the right image's rows)
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from calibration_truth import exp_se3, load_yaml, load_yaml_text, log_se3, t_bs  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
VARIANTS = ['est', 'true', 'cam0', 'cam1', 'stereo', 'imu_rot', 'lever', 'time_gyro', 'camera',
            'imu', 'rows']
SENSORS = ['cam0', 'cam1', 'imu0']


def parse_tbs(text):
    return t_bs(load_yaml_text(text))


def with_tbs(text, m):
    rows = [', '.join(repr(float(v)) for v in m[i]) for i in range(4)]
    block = 'data: [' + ',\n         '.join(rows) + ']'
    new, n = re.subn(r'data: \[[^\]]*\]', block, text, count=1, flags=re.S)
    if n != 1:
        raise ValueError('no T_BS data block')
    return new


def with_line(text, key, value_line):
    new, n = re.subn(rf'^{key}:.*$', value_line, text, flags=re.M)
    if n == 0:
        new = text.rstrip('\n') + '\n' + value_line + '\n'
    return new


def line_of(text, key):
    m = re.search(rf'^{key}:.*$', text, flags=re.M)
    if not m:
        raise ValueError(f'no {key} line')
    return m.group(0)


class Calibrations:
    """The estimate's files, the truth's, and the variants built from them."""

    def __init__(self, render, run):
        self.est = {s: open(os.path.join(run, 'calibration', s, 'sensor.yaml')).read()
                    for s in SENSORS}
        truth = os.path.join(render, 'truth')
        self.true = {s: open(os.path.join(truth, f'{s}_sensor.yaml')).read()
                     for s in ('cam0', 'cam1')}
        draw = load_yaml(os.path.join(truth, 'realism_draw.yaml'))
        gyro = np.array(draw.get('imu_gyro_matrix', np.eye(3)), float)
        self.gyro_scale = [gyro[i, i] - 1.0 for i in range(3)]
        self.time_offset_s = float(draw.get('camera_imu_offset_ms', 0.0)) * 1e-3
        self.b0_est, self.b1_est = parse_tbs(self.est['cam0']), parse_tbs(self.est['cam1'])
        self.b0_true, self.b1_true = parse_tbs(self.true['cam0']), parse_tbs(self.true['cam1'])
        self.file = {s: open(os.path.join(render, 'mav0', s, 'sensor.yaml')).read()
                     for s in ('cam0', 'cam1')}

    def _rows(self, files):
        def intrinsics(text):
            return [float(v) for v in load_yaml_text(text)['intrinsics']]

        def cam0_from_cam1(f):
            return np.linalg.inv(parse_tbs(f['cam0'])) @ parse_tbs(f['cam1'])
        s_true, s_file = cam0_from_cam1(self.true), cam0_from_cam1(self.file)
        rot = np.eye(4)
        rot[:3, :3] = s_true[:3, :3] @ s_file[:3, :3].T
        phi = log_se3(rot)[3:]
        s_est = cam0_from_cam1(files)
        s_new = s_est.copy()
        s_new[:3, :3] = exp_se3([0, 0, 0, phi[0], 0, 0])[:3, :3] @ s_est[:3, :3]
        files['cam1'] = with_tbs(files['cam1'], parse_tbs(files['cam0']) @ s_new)
        c0_est, c0_true = intrinsics(files['cam0']), intrinsics(self.true['cam0'])
        c1 = intrinsics(files['cam1'])
        c1_true = intrinsics(self.true['cam1'])
        c1[1] = c1_true[1] + c0_est[1] - c0_true[1]
        c1[3] = c1_true[3] + c0_est[3] - c0_true[3]
        files['cam1'] = with_line(files['cam1'], 'intrinsics',
                                  'intrinsics: [' + ', '.join(repr(v) for v in c1) + '] #fu, fv, cu, cv')

    def _intrinsics(self, files, cam):
        for key in ('intrinsics', 'distortion_coefficients'):
            files[cam] = with_line(files[cam], key, line_of(self.true[cam], key))

    def _body_from_cam0(self, files, body_from_cam0):
        """Moves cam0 in the body, cam1 with it (the stereo extrinsic of `files` kept)."""
        b0, b1 = parse_tbs(files['cam0']), parse_tbs(files['cam1'])
        files['cam0'] = with_tbs(files['cam0'], body_from_cam0)
        files['cam1'] = with_tbs(files['cam1'], body_from_cam0 @ np.linalg.inv(b0) @ b1)

    def variant(self, name):
        files = dict(self.est)
        parts = {'camera': ['cam0', 'cam1', 'stereo'], 'imu': ['imu_rot', 'lever', 'time_gyro'],
                 'true': ['cam0', 'cam1', 'stereo', 'imu_rot', 'lever', 'time_gyro']}.get(
                     name, [] if name == 'est' else [name])
        for part in parts:
            if part in ('cam0', 'cam1'):
                self._intrinsics(files, part)
            elif part == 'stereo':
                b0 = parse_tbs(files['cam0'])
                files['cam1'] = with_tbs(files['cam1'],
                                         b0 @ np.linalg.inv(self.b0_true) @ self.b1_true)
            elif part in ('imu_rot', 'lever'):
                m = parse_tbs(files['cam0']).copy()
                if part == 'imu_rot':
                    m[:3, :3] = self.b0_true[:3, :3]
                else:
                    m[:3, 3] = self.b0_true[:3, 3]
                self._body_from_cam0(files, m)
            elif part == 'rows':
                self._rows(files)
            elif part == 'time_gyro':
                s = ', '.join(repr(float(v)) for v in self.gyro_scale)
                files['imu0'] = with_line(files['imu0'], 'gyroscope_scale_error', f'gyroscope_scale_error: [{s}]')
                files['cam0'] = with_line(files['cam0'], 'timeshift_cam_imu',
                                          f'timeshift_cam_imu: {self.time_offset_s!r}')
            else:
                raise ValueError(f'unknown variant {name}')
        return files


def make_dataset(render, out, files):
    """OUT: RENDER's data linked, the three sensor.yaml files written."""
    os.makedirs(os.path.join(out, 'mav0'), exist_ok=True)
    render = os.path.abspath(render)

    def link(src, dst):
        if not os.path.lexists(dst):
            os.symlink(src, dst)
    for name in os.listdir(render):
        if name != 'mav0':
            link(os.path.join(render, name), os.path.join(out, name))
    for name in os.listdir(os.path.join(render, 'mav0')):
        src = os.path.join(render, 'mav0', name)
        if name in SENSORS:
            os.makedirs(os.path.join(out, 'mav0', name), exist_ok=True)
            for f in os.listdir(src):
                if f != 'sensor.yaml':
                    link(os.path.join(src, f), os.path.join(out, 'mav0', name, f))
            with open(os.path.join(out, 'mav0', name, 'sensor.yaml'), 'w') as fh:
                fh.write(files[name])
        else:
            link(src, os.path.join(out, 'mav0', name))


def run_one(pkslam, render, dataset, run_dir):
    """ATE (SE(3) alignment, m) and the scale a Sim(3) alignment finds."""
    if not os.path.exists(os.path.join(run_dir, 'trajectory_body.txt')):
        with open(run_dir + '.log', 'w') as log:
            subprocess.run([pkslam, 'run', '--dataset', dataset, '--sensor', 'stereo-inertial',
                            '--calibrate', 'off', '--seed', run_dir.rsplit('seed', 1)[1],
                            '--out', run_dir, '--quiet'],
                           stdout=log, stderr=subprocess.STDOUT, check=True)
    gt = os.path.join(render, 'mav0/state_groundtruth_estimate0/data.csv')
    out = {}
    for align in ('se3', 'sim3'):
        path = os.path.join(run_dir, f'ate_{align}.json')
        if not os.path.exists(path):
            subprocess.run([pkslam, 'eval', '--gt', gt, '--est',
                            os.path.join(run_dir, 'trajectory_body.txt'), '--align', align,
                            '--segments', 'none', '--json', path], capture_output=True, check=True)
        out[align] = json.load(open(path))
    return out['se3']['ate']['rmse'], out['sim3']['scale']


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('render')
    ap.add_argument('run')
    ap.add_argument('out')
    ap.add_argument('--pkslam', default=os.path.join(REPO, 'build', 'bin', 'pkslam'))
    ap.add_argument('--seeds', default='1')
    ap.add_argument('--variants', default=','.join(VARIANTS))
    a = ap.parse_args()
    variants = a.variants.split(',')
    for v in variants:
        if v not in VARIANTS:
            sys.exit(f'residual_sources.py: unknown variant {v} (one of {", ".join(VARIANTS)})')
    seeds = [int(s) for s in a.seeds.split(',')]
    cal = Calibrations(a.render, a.run)
    jobs = []
    for v in variants:
        dataset = os.path.join(a.out, v, 'dataset')
        make_dataset(a.render, dataset, cal.variant(v))
        jobs += [(v, dataset, os.path.join(a.out, v, f'seed{s}')) for s in seeds]
    with ThreadPoolExecutor(max_workers=2) as pool:
        ates = list(pool.map(lambda j: run_one(a.pkslam, a.render, j[1], j[2]), jobs))
    by_variant, scales = {}, {}
    for (v, _, _), (ate, scale) in zip(jobs, ates):
        by_variant.setdefault(v, []).append(ate)
        scales.setdefault(v, []).append(scale)
    print(f'Files: the estimate of {a.run} with one part at the truth; `pkslam run --calibrate off`'
          f' on {a.render}, seeds {a.seeds}.')
    print('| variant | ATE per seed (mm) | median (mm) | map scale error, Sim(3) (%) |')
    print('|---|---|---|---|')
    for v in variants:
        runs = by_variant[v]
        print(f'| {v} | {", ".join(f"{1e3 * x:.2f}" for x in runs)} | '
              f'{1e3 * statistics.median(runs):.2f} | '
              f'{", ".join(f"{100 * (s - 1):+.3f}" for s in scales[v])} |')
    return 0


if __name__ == '__main__':
    sys.exit(main())
