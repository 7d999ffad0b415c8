#!/usr/bin/python3
"""Reads the results.csv of bench/suites/realism.yaml and prints, per trajectory and sensor,
each system's median ATE (SE(3), m) over its runs (a failed run counts as the worst),
coverage and failures, the peer's ratio to
its published real-EuRoC ATE (the preset's bar: 0.5x to 2x) and pkslam's ratio to the peer.

  /usr/bin/python3 evaluation/studies/realism/peer_band.py bench-realism/results.csv [--md OUT.md]
      [--configs orbslam3-peer,orbslam3,pks]

Any bench with the peer reads: the PKS study's (bench/suites/pks-study-eleven.yaml, euroc preset,
5 runs, Sim(3) as its own alignment) too, since the table uses each run's SE(3) ATE column;
--configs keeps the columns named.
"""
import argparse
import csv
import math
import statistics
import sys
from collections import defaultdict

# ORB-SLAM3 paper (arXiv v1), real EuRoC, ATE RMSE (m).
PUBLISHED = {
    'stereo-inertial': {'MH_01': .037, 'MH_02': .031, 'MH_03': .026, 'MH_04': .059, 'MH_05': .086,
                        'V1_01': .037, 'V1_02': .014, 'V1_03': .023, 'V2_01': .037, 'V2_02': .014,
                        'V2_03': .029},
    'mono-inertial': {'MH_01': .032, 'MH_02': .053, 'MH_03': .033, 'MH_04': .099, 'MH_05': .071,
                      'V1_01': .043, 'V1_02': .016, 'V1_03': .025, 'V2_01': .041, 'V2_02': .015,
                      'V2_03': .037},
}
PEER = 'orbslam3-peer'


def sequence_key(dataset):
    for key in PUBLISHED['stereo-inertial']:
        if key in dataset:
            return key
    return None


def band_table(rows, configs=None):
    """(markdown lines, in band, checked) for results.csv rows; `configs` limits the columns."""
    runs = defaultdict(list)
    for row in rows:
        if configs is None or row['config'] in configs:
            runs[(row['dataset'], row['sensor'], row['config'])].append(row)
    configs = sorted({k[2] for k in runs}, key=lambda c: (c != PEER, c))
    lines = ['| sequence | sensor | published | ' +
             ' | '.join(f'{c} ATE [range] (cov., fails)' for c in configs) +
             ' | peer / published | in band | ' +
             ' | '.join(f'{c} / peer' for c in configs if c != PEER) + ' |']
    lines.append('|' + '---|' * (5 + 2 * len(configs) - 1))
    in_band = 0
    checked = 0
    for dataset, sensor in sorted({(k[0], k[1]) for k in runs}):
        key = sequence_key(dataset)
        published = PUBLISHED.get(sensor, {}).get(key)
        medians = {}
        cells = []
        for c in configs:
            rows = runs.get((dataset, sensor, c), [])
            ok = [r for r in rows if r['status'] == 'ok' and r['ate_se3_rmse_m']]
            fails = len(rows) - len(ok)
            if not rows:
                cells.append('')
                continue
            # A failed run counts as the worst result, so failures move the median.
            values = [float(r['ate_se3_rmse_m']) for r in ok] + [math.inf] * fails
            medians[c] = statistics.median(values)
            if math.isinf(medians[c]):
                cells.append(f'failed ({fails} of {len(rows)})')
                continue
            cov = statistics.median(float(r['coverage']) for r in ok)
            spread = f' [{min(values):.3f}-{max(values):.3f}]' if len(values) > 1 else ''
            cells.append(f'{medians[c]:.4f}{spread} ({100 * cov:.0f}%, {fails})')
        peer = medians.get(PEER)
        ratio = peer / published if peer is not None and published else None
        band = ratio is not None and 0.5 <= ratio <= 2.0
        if ratio is not None:
            checked += 1
            in_band += band
        rel = [f'{medians[c] / peer:.2f}'
               if c in medians and peer and not math.isinf(peer) and not math.isinf(medians[c])
               else '' for c in configs if c != PEER]
        ratio_cell = ('failed' if math.isinf(ratio) else f'{ratio:.2f}') if ratio is not None else ''
        band_cell = ('yes' if band else 'no') if ratio is not None else ''
        lines.append(f'| {dataset} | {sensor} | {published if published else ""} | ' +
                     ' | '.join(cells) + f' | {ratio_cell} | {band_cell} | ' + ' | '.join(rel) +
                     ' |')
    lines.append(f'\npeer within 0.5x-2x of its published value: {in_band} of {checked}')
    return lines, in_band, checked


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('results')
    ap.add_argument('--md', help='also write the table as markdown here')
    ap.add_argument('--configs', help='comma-separated columns to keep (default: every one)')
    args = ap.parse_args()
    try:
        with open(args.results, newline='') as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        sys.exit(f'peer_band: {args.results}: {e.strerror}')
    configs = set(args.configs.split(',')) if args.configs else None
    lines, _, _ = band_table(rows, configs)
    text = '\n'.join(lines)
    print(text)
    if args.md:
        with open(args.md, 'w') as f:
            f.write(text + '\n')


if __name__ == '__main__':
    sys.exit(main())
