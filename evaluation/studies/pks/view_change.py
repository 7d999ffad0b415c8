#!/usr/bin/python3
"""Why PKS's delta = 30 deg is (un)reachable: per-frame viewing-angle change of the points
matched to the last keyframe against their parallax (the angle between the rays from the
keyframe and from the frame), from keyframe_trace.csv of `pkslam run --trace` with pks or
pks-released (columns view_change_p50/p90/max, parallax_p50/p90/max, E_c).

For a normal held fixed at the keyframe (pks), the view change of a point is at most its
parallax (triangle inequality on the sphere): no point can become "effective" before the
camera has moved far enough for 30 deg of parallax. pks-released re-estimates the normals every
frame (raw cross-product sums whose sign flips), so its view changes are not bounded that way.

  /usr/bin/python3 evaluation/studies/pks/view_change.py RUN_DIR [RUN_DIR ...] --out view_change.png
"""

import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read(run):
    with open(os.path.join(run, "keyframe_trace.csv"), newline="") as f:
        rows = [r for r in csv.DictReader(f) if r.get("parallax_p90")]
    if not rows:
        sys.exit(f"{run}: keyframe_trace.csv has no view-change columns (run pks with --trace)")

    def col(name):
        return np.array([float(r[name]) if r.get(name) else math.nan for r in rows])

    return rows[0]["selector"], {k: col(k) for k in (
        "parallax_p90", "parallax_max", "view_change_p90", "view_change_max", "E_c")}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("runs", nargs="+")
    p.add_argument("--delta", type=float, default=30.0)
    p.add_argument("--out", required=True)
    a = p.parse_args()
    fig, axes = plt.subplots(1, len(a.runs), figsize=(5.2 * len(a.runs), 4.6), squeeze=False)
    for ax, run in zip(axes[0], a.runs):
        selector, c = read(run)
        top = max(40.0, float(np.nanmax(c["view_change_max"])) * 1.05)
        ax.plot([0, top], [0, top], "k--", lw=1, label="view change = parallax")
        ax.axhline(a.delta, color="C3", lw=1, label=f"delta = {a.delta:g} deg")
        ax.scatter(c["parallax_max"], c["view_change_max"], s=6, alpha=0.35, color="C1",
                   label="per frame: maxima")
        ax.scatter(c["parallax_p90"], c["view_change_p90"], s=6, alpha=0.6, color="C0",
                   label="per frame: 90th percentiles")
        reach = np.mean(c["parallax_max"] >= a.delta)
        effective = np.mean(np.nan_to_num(c["E_c"]) > 0)
        ax.set_xlim(0, max(a.delta * 1.2, float(np.nanmax(c["parallax_max"])) * 1.05))
        ax.set_ylim(0, top)
        ax.set_xlabel("parallax keyframe - frame [deg]")
        ax.set_ylabel("viewing-angle change [deg]")
        ax.set_title(f"{selector}: {len(c['parallax_max'])} frames; parallax >= {a.delta:g} deg "
                     f"in {reach:.1%}, effective points in {effective:.1%}", fontsize=8)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
    fig.savefig(a.out, dpi=110, bbox_inches="tight")
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
