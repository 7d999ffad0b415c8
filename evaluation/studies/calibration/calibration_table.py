#!/usr/bin/python3
"""The tables of docs/calibration.md's "Measurements" from a bench of
bench/suites/calibration.yaml (render.sh's renders):

1. ATE (SE(3), m; median over the runs; a failed run counts as the worst) per trajectory and
   sensor: --calibrate off and online on the render with every error source (all), off and online
   on the render with the true calibration (calibration_off), the ORB-SLAM3 peer on the first, and
   the ratios the issue's bars are about: online(all) / off(calibration_off) (recovery),
   online / off on calibration_off (no harm), online(all) / peer(all).
2. Estimate minus truth per parameter (median over the online runs of |estimate - truth|), with
   the file's error beside it and how many runs freed the parameter.

  PKSLAM_CALIBRATION_RENDERS=RENDERS /usr/bin/python3 \
      evaluation/studies/calibration/calibration_table.py BENCH --peer PEER_BENCH [--md OUT.md]

BENCH is calibration.yaml's bench --out folder (results.csv, or while it runs the finished
runs/DATASET/SENSOR/CONFIG/seedN/result.csv; the runs' stats.json), PEER_BENCH
calibration-peer.yaml's, RENDERS render.sh's folder (the truth of each render).
"""
import argparse
import csv
import json
import math
import os
import statistics
import sys
from collections import defaultdict

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from calibration_truth import truth_parameters  # noqa: E402

TRAJECTORIES = ['MH_01', 'MH_02', 'V1_01', 'V1_02', 'V2_01']
PARAMETER_GROUPS = [
    ('time offset (ms)', ['time_offset'], 0.3),
    ('camera-IMU rotation (deg, per axis)', ['imu.rx', 'imu.ry', 'imu.rz'], 0.03),
    ('camera-IMU translation (mm, per axis)', ['imu.tx', 'imu.ty', 'imu.tz'], 1.0),
    ('stereo rotation (deg, per axis)', ['stereo.rx', 'stereo.ry', 'stereo.rz'], 0.01),
    ('cam0 focal (px)', ['cam0.fx', 'cam0.fy'], 0.2),
    ('cam1 focal (px)', ['cam1.fx'], 0.2),
    ('cam0 principal point (px)', ['cam0.cx', 'cam0.cy'], None),
    ('gyro scale factor (%, per axis)', ['gyro.sx', 'gyro.sy', 'gyro.sz'], None),
    ('accelerometer scale factor (%, per axis)', ['accel.sx', 'accel.sy', 'accel.sz'], None),
    ('accelerometer misalignment (deg, per term)',
     ['accel.mxy', 'accel.mxz', 'accel.myx', 'accel.myz', 'accel.mzx', 'accel.mzy'], None),
]


def warned(calibration, threshold=3.0):
    """The parameters system/calibration_outputs.cc's CalibrationWarnings names: free, file more
    than 3 sigma from the estimate, the sigma at least a third of the prior's (the third alone
    without covariance). Recomputed here so runs of an earlier rule count by today's."""
    out = []
    for p in calibration.get('parameters', []):
        if not p.get('free'):
            continue
        posterior = p['sigma'] if calibration.get('covariance') and p['sigma'] > 0 else 0.0
        sigma = max(posterior, p['prior_sigma'] / 3.0)
        if sigma > 0 and abs(p['file'] - p['estimate']) / sigma > threshold:
            out.append(p['name'])
    return out


def online_calibrations(bench, dataset, sensor):
    """The stats.json "calibration" sections of a cell's online runs, in seed order."""
    base = os.path.join(bench, 'runs', dataset, sensor, 'online')
    out = []
    for seed in sorted(os.listdir(base)) if os.path.isdir(base) else []:
        stats = os.path.join(base, seed, 'stats.json')
        if os.path.isfile(stats):
            with open(stats) as f:
                out.append(json.load(f).get('calibration', {}))
    return out


def warnings_table(bench):
    """Per render and sensor: online runs, runs whose covariance succeeded, warnings per run
    (today's rule) and which parameters they named."""
    lines = ['| render | sensor | online runs | covariance computed | warnings per run | parameters '
             'warned (runs) |', '|---|---|---|---|---|---|']
    for t in TRAJECTORIES:
        for variant in ('all', 'calibration_off'):
            for s in ('stereo-inertial', 'mono-inertial'):
                runs = cov = 0
                names = defaultdict(int)
                for cal in online_calibrations(bench, f'{t}_{variant}', s):
                    runs += 1
                    cov += 1 if cal.get('covariance') else 0
                    for n in warned(cal):
                        names[n] += 1
                if runs:
                    total = sum(names.values())
                    lines.append(f'| {t}_{variant} | {s} | {runs} | {cov} | {total / runs:.1f} | ' +
                                 ', '.join(f'{n} ({c})' for n, c in sorted(names.items())) + ' |')
    return '\n'.join(lines)


def median_worst(values, failures):
    """Median with each failed run as +inf (the worst)."""
    v = sorted(values + [math.inf] * failures)
    return statistics.median(v) if v else None


def fmt(x, digits=4):
    if x is None:
        return ''
    return 'failed' if math.isinf(x) else f'{x:.{digits}f}'


def ratio(a, b):
    if a is None or b is None or b == 0 or math.isinf(b):
        return None
    return a / b


def result_rows(bench):
    """results.csv, or while the bench is still running the finished runs' result.csv files."""
    path = os.path.join(bench, 'results.csv')
    files = [path] if os.path.isfile(path) else sorted(
        os.path.join(d, 'result.csv') for d, _, names in os.walk(os.path.join(bench, 'runs'))
        if 'result.csv' in names)
    for name in files:
        with open(name) as f:
            yield from csv.DictReader(f)


def read_results(benches):
    ate = defaultdict(list)
    failed = defaultdict(int)
    rt = defaultdict(list)
    for row in (r for b in benches for r in result_rows(b)):
        trajectory, variant = row['dataset'][:5], row['dataset'][6:]
        key = (trajectory, row['sensor'], variant, row['config'])
        if row['status'] == 'ok' and row['ate_se3_rmse_m']:
            ate[key].append(float(row['ate_se3_rmse_m']))
            if row.get('cpu_s') and row.get('mapping_cpu_s'):
                rt[key].append((float(row['cpu_s']), float(row['mapping_cpu_s'])))
        else:
            failed[key] += 1
    return ate, failed, rt


def ate_table(ate, failed, rt):
    med = {k: median_worst(ate.get(k, []), failed.get(k, 0)) for k in set(ate) | set(failed)}
    lines = ['| trajectory | sensor | off | online | off, true cal. | online, true cal. | peer | '
             'online / off true cal. (<= 1.3) | no harm: online / off, true cal. (<= 1.05) | '
             'online / peer | CPU s online / off: process, local mapping |',
             '|' + '---|' * 11]
    sensors = sorted({k[1] for k in med}, reverse=True)
    for s in sensors:
        for t in TRAJECTORIES:
            g = lambda v, c: med.get((t, s, v, c))  # noqa: E731
            off, on = g('all', 'off'), g('all', 'online')
            toff, ton = g('calibration_off', 'off'), g('calibration_off', 'online')
            peer = g('all', 'orbslam3-peer')
            if off is None and on is None:
                continue
            rt_on = rt.get((t, s, 'all', 'online'), [])
            rt_off = rt.get((t, s, 'all', 'off'), [])
            cpu = (f'{statistics.median(c for c, _ in rt_on) / statistics.median(c for c, _ in rt_off):.2f}, '
                   f'{statistics.median(m for _, m in rt_on) / statistics.median(m for _, m in rt_off):.2f}'
                   if rt_on and rt_off else '')
            cells = [fmt(off), fmt(on), fmt(toff), fmt(ton), fmt(peer),
                     fmt(ratio(on, toff), 2), fmt(ratio(ton, toff), 2), fmt(ratio(on, peer), 2),
                     cpu]
            lines.append(f'| {t} | {s} | ' + ' | '.join(cells) + ' |')
    return '\n'.join(lines)


def truth_table(bench):
    """Median |estimate - truth| of the online runs on the NAME_all renders."""
    renders = os.environ.get('PKSLAM_CALIBRATION_RENDERS')
    rows = []
    for t in TRAJECTORIES:
        for s in ['stereo-inertial', 'mono-inertial']:
            calibrations = online_calibrations(bench, f'{t}_all', s)
            if not calibrations:
                continue
            seq = os.path.join(renders, f'{t}_all') if renders else None
            if not seq or not os.path.isdir(seq):
                print(f'calibration_table: set PKSLAM_CALIBRATION_RENDERS to the renders '
                      f'({t}_all not found)', file=sys.stderr)
                return ''
            truth = truth_parameters(seq)
            err = defaultdict(list)
            file_err = {}
            freed = defaultdict(int)
            frozen = defaultdict(set)
            runs = 0
            for cal in calibrations:
                runs += 1
                for group, why in cal.get('frozen', {}).items():
                    frozen[group].add(why)
                for p in cal.get('parameters', []):
                    n = p['name']
                    if n not in truth:
                        continue
                    err[n].append(abs(p['estimate'] - truth[n]))
                    file_err[n] = abs(p['file'] - truth[n])
                    freed[n] += 1 if p.get('free') else 0
            cells = []
            for _, names, _ in PARAMETER_GROUPS:
                present = [n for n in names if n in err]
                if not present:
                    cells.append('')
                    continue
                est = max(statistics.median(err[n]) for n in present)
                fil = max(file_err[n] for n in present)
                fr = max(freed[n] for n in present)
                cells.append(f'{est:.3f} (file {fil:.3f}; freed {fr}/{runs})')
            cells.append('; '.join(f'{g}: {" / ".join(sorted(w))}' for g, w in sorted(frozen.items())))
            rows.append(f'| {t} | {s} | ' + ' | '.join(cells) + ' |')
    header = ('| trajectory | sensor | ' + ' | '.join(
        f'{name}' + (f' (bar {bar})' if bar is not None else '') for name, _, bar in PARAMETER_GROUPS)
        + ' | frozen in some run (why) |')
    return '\n'.join([header, '|' + '---|' * (3 + len(PARAMETER_GROUPS))] + rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('bench')
    ap.add_argument('--peer', help="calibration-peer.yaml's bench folder")
    ap.add_argument('--md', help='also write the tables as markdown here')
    args = ap.parse_args()
    ate, failed, rt = read_results([args.bench] + ([args.peer] if args.peer else []))
    text = ('ATE (m, SE(3), median of the runs; failed = worst)\n\n' + ate_table(ate, failed, rt) +
            '\n\nEstimate - truth (median over the online runs of |estimate - truth|; per group '
            'the worst axis)\n\n' + truth_table(args.bench) +
            '\n\nWarnings (today\'s rule, recomputed from stats.json)\n\n' + warnings_table(args.bench))
    print(text)
    if args.md:
        with open(args.md, 'w') as f:
            f.write(text + '\n')


if __name__ == '__main__':
    main()
