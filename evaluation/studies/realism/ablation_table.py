#!/usr/bin/python3
"""Reads the results.csv of evaluation/suites/realism-ablation.yaml and prints the ablation table:
per trajectory, sensor and system the ATE (SE(3), m; median over runs) with every error source on,
with none, and with each source switched off in turn, plus how much of the gap between ideal and
all each source explains (all - source_off).

  /usr/bin/python3 evaluation/studies/realism/ablation_table.py bench-ablation/results.csv [--md OUT.md]
"""
import argparse
import csv
import statistics
from collections import defaultdict

VARIANTS = ['all', 'ideal', 'appearance_off', 'calibration_off', 'timing_off', 'imu_off',
            'motion_off', 'ground_truth_off']


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('results')
    ap.add_argument('--md', help='also write the table as markdown here')
    args = ap.parse_args()
    ate = defaultdict(list)
    failed = defaultdict(int)
    with open(args.results) as f:
        for row in csv.DictReader(f):
            parts = row['dataset'].split('_')  # V1_02_calibration_off
            trajectory, variant = '_'.join(parts[:2]), '_'.join(parts[2:])
            key = (trajectory, row['sensor'], row['config'], variant)
            if row['status'] == 'ok' and row['ate_se3_rmse_m']:
                ate[key].append(float(row['ate_se3_rmse_m']))
            else:
                failed[key] += 1
    groups = sorted({k[:3] for k in list(ate) + list(failed)})
    lines = ['| trajectory | sensor | system | ' + ' | '.join(VARIANTS) + ' |',
             '|' + '---|' * (3 + len(VARIANTS))]
    for g in groups:
        cells = []
        for v in VARIANTS:
            values = ate.get(g + (v,), [])
            if values:
                cells.append(f'{statistics.median(values):.4f}')
            elif failed.get(g + (v,)):
                cells.append('failed')
            else:
                cells.append('')
        lines.append(f'| {g[0]} | {g[1]} | {g[2]} | ' + ' | '.join(cells) + ' |')
    text = '\n'.join(lines)
    print(text)
    if args.md:
        with open(args.md, 'w') as f:
            f.write(text + '\n')


if __name__ == '__main__':
    main()
