#!/usr/bin/python3
"""How well a run's own "suspect" flag (stats.json "estimate", system/estimate_health.h) tells
the runs that went wrong, against ground truth: a 2x2 table of suspect against ATE above a
threshold, per sensor, from a bench's results.csv (after `pkslam bench SUITE --out OUT
--reevaluate` for runs made before the flag).

  /usr/bin/python3 evaluation/studies/robustness/suspect_vs_ate.py OUT/results.csv [--ate 0.1]
"""

import argparse
import csv
import math
import os
import sys

REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..")
sys.path.insert(0, os.path.join(REPO, "bench"))
from bench_statistics import number  # noqa: E402  (bench/bench_statistics.py)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("results")
    parser.add_argument("--ate", type=float, default=0.1, help="ATE [m] that counts as wrong")
    args = parser.parse_args()
    try:
        with open(args.results, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        sys.exit(f"suspect_vs_ate: {args.results}: {e.strerror}")
    if rows and "suspect" not in rows[0]:
        sys.exit(f"suspect_vs_ate: {args.results}: no 'suspect' column (re-run the bench with "
                 "--reevaluate)")
    rows = [r for r in rows if r["status"] == "ok" and math.isfinite(number(r["ate_m"]))
            and math.isfinite(number(r.get("suspect")))]
    if not rows:
        sys.exit(f"suspect_vs_ate: {args.results}: no successful run with a suspect flag")
    print(f"| sensor | runs | ATE > {args.ate} m | flagged among them | flagged among the rest |")
    print("|---|---|---|---|---|")
    for sensor in sorted({r["sensor"] for r in rows}) + ["all"]:
        g = [r for r in rows if sensor == "all" or r["sensor"] == sensor]
        wrong = [r for r in g if number(r["ate_m"]) > args.ate]
        right = [r for r in g if number(r["ate_m"]) <= args.ate]
        flagged = lambda group: sum(1 for r in group if number(r["suspect"]) == 1)  # noqa: E731
        print(f"| {sensor} | {len(g)} | {len(wrong)} | {flagged(wrong)} of {len(wrong)} | "
              f"{flagged(right)} of {len(right)} |")


if __name__ == "__main__":
    main()
