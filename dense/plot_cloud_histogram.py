#!/usr/bin/python3
"""Histogram of cloud-comparison distances (called by pkslam cloud-compare --hist).

Usage: plot_cloud_histogram.py OUT.png TITLE MAX_CM LABEL1 FILE1 [LABEL2 FILE2 ...]
Each FILE holds little-endian float32 distances in metres.
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(argv):
    if len(argv) < 6 or (len(argv) - 4) % 2 != 0:
        sys.stderr.write(__doc__)
        return 2
    out, title, max_cm = argv[1], argv[2], float(argv[3])
    fig, ax = plt.subplots(figsize=(7, 4.2), dpi=120)
    bins = np.linspace(0.0, max_cm, 61)
    for label, path in zip(argv[4::2], argv[5::2]):
        d_cm = np.fromfile(path, dtype="<f4") * 100.0
        if d_cm.size == 0:
            continue
        stats = "n={:,}  mean {:.2f} cm  median {:.2f} cm".format(
            d_cm.size, d_cm.mean(), np.median(d_cm))
        weights = np.full(d_cm.size, 100.0 / d_cm.size)
        ax.hist(np.clip(d_cm, 0.0, max_cm), bins=bins, weights=weights, histtype="step",
                linewidth=1.6, label="{}: {}".format(label, stats))
    ax.set_xlabel("nearest-neighbour distance [cm] (last bin: >= {:g} cm)".format(max_cm))
    ax.set_ylabel("share of points [%]")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
