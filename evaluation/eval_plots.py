#!/usr/bin/python3
"""Figures for `pkslam eval --plot DIR` (Debian python3-matplotlib + python3-numpy).

Reads DIR/data/estimates.tsv and the per-estimate files `pkslam eval` wrote beside it
(LABEL_poses.csv, LABEL_rpe.csv, LABEL_segments.csv; evaluation/evaluation_output.h), draws
the figures evo_traj / evo_ape / evo_rpe / evo_res and rpg_trajectory_evaluation users look at,
and lists them in DIR/figures.tsv (file<TAB>caption):

  trajectories_top.png   top view (x-y) of the aligned estimates and the truth
  trajectories_xyz.png   x, y, z over time
  trajectories_rpy.png   roll, pitch, yaw over time (unwrapped)
  ate_over_time.png      ATE translation and rotation over time (single estimate: rmse, median,
                         mean lines as evo_ape draws them)
  ate_along_path.png     each estimate's top view coloured by its ATE (one colour scale)
  rpe_over_time.png      RPE translation and rotation at each pair's end time
  segment_errors.png     relative error over segment lengths, box plots per estimate (rpg)
  ate_box.png            the ATE distribution of each estimate (evo_res)

  /usr/bin/python3 evaluation/eval_plots.py --data DIR/data --out DIR
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
from matplotlib.collections import LineCollection  # noqa: E402

DPI = 110
TRUTH_STYLE = {"color": "0.25", "linestyle": "--", "linewidth": 1.2, "label": "ground truth"}


def read_csv(path):
    """Columns of a CSV as float arrays (empty arrays for a file with only its header)."""
    if not os.path.exists(path):
        return None
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader, None)
        rows = [r for r in reader if r]
    if header is None:
        return None
    table = np.array([[float(v) for v in r] for r in rows], dtype=float).reshape(-1, len(header))
    return {name: table[:, k] for k, name in enumerate(header)}


def read_estimates(data_dir):
    index = os.path.join(data_dir, "estimates.tsv")
    with open(index, newline="") as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    if not rows:
        raise SystemExit(f"{index}: no estimate listed")
    estimates = []
    for row in rows:
        label = row["label"]
        poses = read_csv(os.path.join(data_dir, f"{label}_poses.csv"))
        if poses is None or len(poses["t_s"]) == 0:
            raise SystemExit(f"{data_dir}/{label}_poses.csv: missing or empty")
        estimates.append({
            "label": label,
            "alignment": row.get("alignment", ""),
            "poses": poses,
            "rpe": read_csv(os.path.join(data_dir, f"{label}_rpe.csv")),
            "segments": read_csv(os.path.join(data_dir, f"{label}_segments.csv")),
        })
    return estimates


class Figures:
    def __init__(self, out):
        self.out = out
        self.index = []

    def save(self, fig, name, caption):
        fig.tight_layout()
        fig.savefig(os.path.join(self.out, name), dpi=DPI)
        plt.close(fig)
        self.index.append((name, caption))

    def write_index(self):
        with open(os.path.join(self.out, "figures.tsv"), "w") as f:
            for name, caption in self.index:
                f.write(f"{name}\t{caption}\n")


def relative_time(estimates):
    """Seconds since the earliest matched pose of any estimate (evo's plots start at 0)."""
    return min(e["poses"]["t_s"][0] for e in estimates)


def colours(n):
    cmap = plt.get_cmap("tab10")
    return [cmap(k % 10) for k in range(n)]


def truth_of(estimates):
    """The truth of the estimate with the most matched poses (all share one ground truth)."""
    return max(estimates, key=lambda e: len(e["poses"]["t_s"]))["poses"]


def top_view(figs, estimates, t0):
    fig, ax = plt.subplots(figsize=(7, 6))
    gt = truth_of(estimates)
    ax.plot(gt["gt_x"], gt["gt_y"], **TRUTH_STYLE)
    for e, c in zip(estimates, colours(len(estimates))):
        p = e["poses"]
        ax.plot(p["est_x"], p["est_y"], color=c, linewidth=1.0, label=e["label"])
    ax.plot(gt["gt_x"][0], gt["gt_y"][0], "ko", markersize=5, label="start")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(f"Top view, aligned ({estimates[0]['alignment']})")
    figs.save(fig, "trajectories_top.png", "Top view of the aligned estimates and the truth")


def over_time(figs, estimates, t0, columns, ylabels, name, caption, unwrap=False):
    fig, axes = plt.subplots(len(columns), 1, figsize=(9, 2.4 * len(columns)), sharex=True)
    gt = truth_of(estimates)
    for ax, (gt_col, est_col), ylabel in zip(axes, columns, ylabels):
        series = gt[gt_col]
        if unwrap:
            series = np.degrees(np.unwrap(np.radians(series)))
        ax.plot(gt["t_s"] - t0, series, **TRUTH_STYLE)
        for e, c in zip(estimates, colours(len(estimates))):
            p = e["poses"]
            values = p[est_col]
            if unwrap:
                values = np.degrees(np.unwrap(np.radians(values)))
            ax.plot(p["t_s"] - t0, values, color=c, linewidth=1.0, label=e["label"])
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=8, loc="best")
    axes[-1].set_xlabel("time [s]")
    figs.save(fig, name, caption)


def statistic_lines(ax, values, unit):
    rmse = math.sqrt(float(np.mean(np.square(values))))
    for value, style, name in ((rmse, "-", "rmse"), (float(np.median(values)), "--", "median"),
                               (float(np.mean(values)), ":", "mean")):
        ax.axhline(value, color="0.4", linestyle=style, linewidth=1.0,
                   label=f"{name} {value:.4g} {unit}")


def ate_over_time(figs, estimates, t0):
    fig, axes = plt.subplots(2, 1, figsize=(9, 5.5), sharex=True)
    for e, c in zip(estimates, colours(len(estimates))):
        p = e["poses"]
        axes[0].plot(p["t_s"] - t0, p["ate_m"], color=c, linewidth=1.0, label=e["label"])
        axes[1].plot(p["t_s"] - t0, p["ate_rot_deg"], color=c, linewidth=1.0, label=e["label"])
    if len(estimates) == 1:
        statistic_lines(axes[0], estimates[0]["poses"]["ate_m"], "m")
        statistic_lines(axes[1], estimates[0]["poses"]["ate_rot_deg"], "deg")
    axes[0].set_ylabel("ATE translation [m]")
    axes[1].set_ylabel("ATE rotation [deg]")
    axes[1].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="upper left")
    figs.save(fig, "ate_over_time.png", "Absolute error over time (translation, rotation)")


def ate_along_path(figs, estimates):
    n = len(estimates)
    cols = min(n, 3)
    rows = int(math.ceil(n / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(5.2 * cols, 4.6 * rows), squeeze=False)
    top = max(float(np.max(e["poses"]["ate_m"])) for e in estimates)
    norm = plt.Normalize(0.0, top if top > 0 else 1.0)
    gt = truth_of(estimates)
    line = None
    for k, ax in enumerate(axes.flat):
        if k >= n:
            ax.axis("off")
            continue
        p = estimates[k]["poses"]
        ax.plot(gt["gt_x"], gt["gt_y"], color="0.6", linestyle="--", linewidth=0.8)
        points = np.column_stack([p["est_x"], p["est_y"]]).reshape(-1, 1, 2)
        segments = np.concatenate([points[:-1], points[1:]], axis=1)
        line = LineCollection(segments, cmap="jet", norm=norm, linewidth=2.0)
        line.set_array(p["ate_m"][1:])
        ax.add_collection(line)
        ax.autoscale()
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(estimates[k]["label"], fontsize=9)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.grid(True, alpha=0.3)
    fig.colorbar(line, ax=axes.ravel().tolist(), label="ATE translation [m]")
    # tight_layout does not know the shared colour bar; save without it.
    fig.savefig(os.path.join(figs.out, "ate_along_path.png"), dpi=DPI)
    plt.close(fig)
    figs.index.append(("ate_along_path.png",
                       "Each estimate's path coloured by its ATE (grey dashes: the truth)"))


def rpe_over_time(figs, estimates, t0):
    have = [e for e in estimates if e["rpe"] is not None and len(e["rpe"]["t_end_s"]) > 0]
    if not have:
        return
    fig, axes = plt.subplots(2, 1, figsize=(9, 5.5), sharex=True)
    for e, c in zip(estimates, colours(len(estimates))):
        if e not in have:
            continue
        r = e["rpe"]
        axes[0].plot(r["t_end_s"] - t0, r["trans_m"], color=c, linewidth=0.8, label=e["label"])
        axes[1].plot(r["t_end_s"] - t0, r["rot_deg"], color=c, linewidth=0.8, label=e["label"])
    axes[0].set_ylabel("RPE translation [m]")
    axes[1].set_ylabel("RPE rotation [deg]")
    axes[1].set_xlabel("time of the pair's end [s]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="upper left")
    figs.save(fig, "rpe_over_time.png", "Relative error of each pose pair over time")


def grouped_boxes(ax, groups, labels, positions_of, colour_list):
    """groups[k][g]: values of estimate k in group g; one box per (group, estimate)."""
    n = len(labels)
    width = 0.8 / n
    for k in range(n):
        data = [values if len(values) else [np.nan] for values in groups[k]]
        pos = [positions_of(g) + (k - (n - 1) / 2) * width for g in range(len(groups[k]))]
        box = ax.boxplot(data, positions=pos, widths=width * 0.9, patch_artist=True,
                         showfliers=False, manage_ticks=False)
        for patch in box["boxes"]:
            patch.set_facecolor(colour_list[k])
            patch.set_alpha(0.6)
        ax.plot([], [], color=colour_list[k], linewidth=6, alpha=0.6, label=labels[k])


def segment_errors(figs, estimates):
    have = [e for e in estimates
            if e["segments"] is not None and len(e["segments"]["length_m"]) > 0]
    if not have:
        return
    lengths = sorted({float(v) for e in have for v in e["segments"]["length_m"]})
    cs = colours(len(estimates))
    fig, axes = plt.subplots(2, 1, figsize=(max(7, 1.6 * len(lengths) + 2), 6.5), sharex=True)
    for ax, column, ylabel in ((axes[0], "trans_m", "translation error [m]"),
                               (axes[1], "rot_deg", "rotation error [deg]")):
        groups = []
        for e in have:
            s = e["segments"]
            groups.append([s[column][np.isclose(s["length_m"], length)] for length in lengths])
        grouped_boxes(ax, groups, [e["label"] for e in have], lambda g: g,
                      [cs[estimates.index(e)] for e in have])
        ax.set_ylabel(ylabel)
        ax.grid(True, axis="y", alpha=0.3)
    axes[0].legend(fontsize=8, loc="upper left")
    axes[1].set_xticks(range(len(lengths)))
    axes[1].set_xticklabels([f"{v:g}" for v in lengths])
    axes[1].set_xlabel("distance travelled [m] (segment length)")
    figs.save(fig, "segment_errors.png",
              "Relative error over segment lengths (rpg_trajectory_evaluation), per estimate")


def ate_box(figs, estimates):
    fig, ax = plt.subplots(figsize=(max(5, 1.2 * len(estimates) + 2), 4.5))
    box = ax.boxplot([e["poses"]["ate_m"] for e in estimates], patch_artist=True,
                     showfliers=True, flierprops={"markersize": 2})
    for patch, c in zip(box["boxes"], colours(len(estimates))):
        patch.set_facecolor(c)
        patch.set_alpha(0.6)
    ax.set_xticks(range(1, len(estimates) + 1))
    ax.set_xticklabels([e["label"] for e in estimates], rotation=20, ha="right", fontsize=8)
    ax.set_ylabel("ATE translation [m]")
    ax.grid(True, axis="y", alpha=0.3)
    figs.save(fig, "ate_box.png", "ATE distribution per estimate (boxes: quartiles)")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--data", required=True, help="the folder pkslam eval wrote (DIR/data)")
    p.add_argument("--out", required=True, help="where the PNGs and figures.tsv go")
    args = p.parse_args(argv)
    estimates = read_estimates(args.data)
    os.makedirs(args.out, exist_ok=True)
    figs = Figures(args.out)
    t0 = relative_time(estimates)
    top_view(figs, estimates, t0)
    over_time(figs, estimates, t0, [("gt_x", "est_x"), ("gt_y", "est_y"), ("gt_z", "est_z")],
              ["x [m]", "y [m]", "z [m]"], "trajectories_xyz.png",
              "Position over time against the truth")
    over_time(figs, estimates, t0,
              [("gt_roll_deg", "est_roll_deg"), ("gt_pitch_deg", "est_pitch_deg"),
               ("gt_yaw_deg", "est_yaw_deg")],
              ["roll [deg]", "pitch [deg]", "yaw [deg]"], "trajectories_rpy.png",
              "Orientation (roll, pitch, yaw) over time against the truth", unwrap=True)
    ate_over_time(figs, estimates, t0)
    ate_along_path(figs, estimates)
    rpe_over_time(figs, estimates, t0)
    segment_errors(figs, estimates)
    ate_box(figs, estimates)
    figs.write_index()
    for name, _ in figs.index:
        print(os.path.join(args.out, name))
    return 0


if __name__ == "__main__":
    sys.exit(main())
