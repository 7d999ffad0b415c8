#!/usr/bin/env python3
"""Fits live emulation's work clock (core/util/work_meter.h, mapping/local_mapper.cc
kReferenceWork): CPU seconds of local mapping per unit of work, from runs' stats.json
(per keyframe: local_mapping_cpu_ms and local_mapping_work), by non-negative least squares.

    /usr/bin/python3 evaluation/studies/coupling/fit_work_model.py RUN_DIR...

Prints the prices, the fit's quality per run (total modelled / measured CPU seconds; median
relative error per keyframe) and the C++ initialiser to paste.
"""
import json
import sys

import numpy as np
from scipy.optimize import nnls

KINDS = ["keyframe", "triangulation keypoints", "fused projections", "solver residuals"]


def load(run):
    s = json.load(open(f"{run}/stats.json"))
    cpu = np.array(s["local_mapping_cpu_ms"], dtype=float) * 1e-3
    work = np.array(s["local_mapping_work"], dtype=float)
    if len(cpu) != len(work) or len(cpu) == 0:
        sys.exit(f"{run}/stats.json: no per-keyframe work to fit (a run of a build before it)")
    return cpu, work


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    runs = {r: load(r) for r in sys.argv[1:]}
    cpu = np.concatenate([c for c, _ in runs.values()])
    work = np.concatenate([w for _, w in runs.values()])
    # Relative error matters (a keyframe of 5 ms and one of 500 ms), but the clock's totals are
    # dominated by the long ones: weight by 1/sqrt(cpu) as a compromise.
    weight = 1.0 / np.sqrt(np.maximum(cpu, 1e-3))
    prices, _ = nnls(work * weight[:, None], cpu * weight)
    for kind, p in zip(KINDS, prices):
        print(f"{kind:>24}: {p:.3e} s per unit")
    print(f"{'run':>40} {'keyframes':>9} {'cpu s':>7} {'model s':>7} {'ratio':>6} {'median |rel|':>12}")
    for run, (c, w) in runs.items():
        m = w @ prices
        rel = np.abs(m - c) / np.maximum(c, 1e-4)
        print(f"{run[-40:]:>40} {len(c):9d} {c.sum():7.2f} {m.sum():7.2f} "
              f"{m.sum() / c.sum():6.2f} {np.median(rel):12.2f}")
    print("const WorkModel kReferenceWork{{" + ", ".join(f"{p:.4g}" for p in prices) + "}};")


if __name__ == "__main__":
    main()
