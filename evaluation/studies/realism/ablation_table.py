#!/usr/bin/python3
"""Reads the results.csv of bench/suites/realism-ablation.yaml and prints the ablation table:
per trajectory, sensor and system the ATE (SE(3), m; median over runs, range in brackets when
there are several; a failed run counts as the worst) with every error source on, with none, and
with each source switched off in turn. Then, per source, whether switching it off is resolved
from the run-to-run spread: the runs with the source off all lie below (or all above) the runs
with every source on, so the ranges do not overlap.

  /usr/bin/python3 evaluation/studies/realism/ablation_table.py bench-ablation/results.csv [--md OUT.md]
"""
import argparse
import csv
import statistics
from collections import defaultdict

VARIANTS = ['all', 'ideal', 'appearance_off', 'calibration_off', 'timing_off', 'imu_off',
            'motion_off', 'ground_truth_off']


def ate_text(ate, failed):
    """An ATE for the table; a failed run (counted as infinite, the worst) as `failed`."""
    return failed if ate == float('inf') else f'{ate:.4f}'


def build_table(rows):
    """rows: dicts with dataset, sensor, config, status, ate_se3_rmse_m (results.csv's columns)."""
    ate = defaultdict(list)
    failed = defaultdict(int)
    for row in rows:
        parts = row['dataset'].split('_')  # V1_02_calibration_off
        trajectory, variant = '_'.join(parts[:2]), '_'.join(parts[2:])
        key = (trajectory, row['sensor'], row['config'], variant)
        if row['status'] == 'ok' and row['ate_se3_rmse_m']:
            ate[key].append(float(row['ate_se3_rmse_m']))
        else:
            failed[key] += 1
    groups = sorted({k[:3] for k in list(ate) + list(failed)})

    def runs(key):
        return sorted(ate.get(key, [])) + [float('inf')] * failed.get(key, 0)

    def cell(values):
        if not values:
            return ''
        text = ate_text(statistics.median(values), 'failed')
        if len(values) > 1:
            text += f' [{ate_text(values[0], "fail")}-{ate_text(values[-1], "fail")}]'
        return text

    lines = ['| trajectory | sensor | system | ' + ' | '.join(VARIANTS) + ' |',
             '|' + '---|' * (3 + len(VARIANTS))]
    verdicts = []
    for g in groups:
        lines.append(f'| {g[0]} | {g[1]} | {g[2]} | ' +
                     ' | '.join(cell(runs(g + (v,))) for v in VARIANTS) + ' |')
        base = runs(g + ('all',))
        for v in VARIANTS[1:]:
            off = runs(g + (v,))
            if len(base) < 2 or len(off) < 2:
                continue
            if off[-1] < base[0]:
                verdict = f'lower ({statistics.median(off) / statistics.median(base):.2f}x), resolved'
            elif off[0] > base[-1]:
                verdict = f'higher ({statistics.median(off) / statistics.median(base):.2f}x), resolved'
            else:
                verdict = 'within the run-to-run spread'
            verdicts.append(f'{g[0]} {g[1]} {g[2]}: {v} -> {verdict}')
    text = '\n'.join(lines)
    if verdicts:
        text += '\n\nSwitching one source off, against every source on (non-overlapping ranges = resolved):\n'
        text += '\n'.join('- ' + v for v in verdicts)
    return text


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('results')
    ap.add_argument('--md', help='also write the table as markdown here')
    args = ap.parse_args()
    with open(args.results) as f:
        text = build_table(csv.DictReader(f))
    print(text)
    if args.md:
        with open(args.md, 'w') as f:
            f.write(text + '\n')


if __name__ == '__main__':
    main()
