#!/usr/bin/env python3
"""Median ATE, frames with a pose and real-time factor per replay, sensor, coupling and core
count from evaluation/studies/coupling/cores.sh's cores.tsv, with the ratio of the one-core to
the two-core median (issue 37's bar: within 15%).

    /usr/bin/python3 evaluation/studies/coupling/cores_table.py OUT/cores.tsv
"""
import csv
import math
import statistics
import sys
from collections import defaultdict


def main():
    if len(sys.argv) != 2:
        print(__doc__)
        return 2
    cells = defaultdict(list)
    with open(sys.argv[1]) as f:
        for row in csv.DictReader(f, delimiter="\t"):
            ate = float(row["ate_m"])
            # A failed run (no trajectory, exit != 0) counts as the worst: infinite error.
            if math.isnan(ate) or row["exit"] not in ("0",):
                ate = math.inf
            cells[(row["replay"], row["sensor"], row["coupling"], row["cores"])].append(
                (ate, int(row["posed"]), int(row["frames"]), float(row["realtime"])))
    print("| replay | sensor | coupling | 1 core: median ATE (runs) | 2 cores | ratio | "
          "real-time 1 / 2 cores |")
    print("|---|---|---|---|---|---|---|")
    keys = sorted({k[:3] for k in cells})
    for replay, sensor, coupling in keys:
        one = cells.get((replay, sensor, coupling, "0"), [])
        two = cells.get((replay, sensor, coupling, "0-1"), [])
        fmt = lambda v: f"{1e3 * v:.1f} mm" if math.isfinite(v) else "failed"

        def cell(runs):
            if not runs:
                return "-", math.nan, "-"
            m = statistics.median(a for a, *_ in runs)
            rt = statistics.median(r for *_, r in runs)
            return f"{fmt(m)} ({', '.join(fmt(a) for a, *_ in runs)})", m, f"{rt:.2f}x"

        text1, m1, rt1 = cell(one)
        text2, m2, rt2 = cell(two)
        ratio = m1 / m2 if math.isfinite(m1) and math.isfinite(m2) and m2 > 0 else math.nan
        ratio_text = f"{ratio:.2f}" if math.isfinite(ratio) else "-"
        print(f"| {replay} | {sensor} | {coupling} | {text1} | {text2} | {ratio_text} | "
              f"{rt1} / {rt2} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
