#!/usr/bin/python3
"""Plots for `pkslam bench` reports (Debian python3-matplotlib + python3-numpy).

Reads OUT/results.csv (one row per run) and the run folders' plot_trajectory.csv /
plot_keyframes.csv (written by the harness), writes PNGs into --out and an index.tsv listing
`file<TAB>section<TAB>caption` per PNG, which report.md / report.html embed.

  /usr/bin/python3 bench/plots.py --results OUT/results.csv --runs OUT/runs --out OUT/plots
"""

import argparse
import csv
import html
import json
import math
import os
import sys
from collections import OrderedDict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

DPI = 110


def number(text):
    try:
        v = float(text)
    except (TypeError, ValueError):
        return math.nan
    return v


def read_results(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        r["ok"] = r["status"] == "ok"
        for k in ("ate_m", "keyframes", "median_tracking_ms", "wall_s", "sweep_value"):
            r[k] = number(r[k])
        # Absent in results.csv files written before the PKS study columns.
        for k in ("sequence_s", "mapping_cpu_s", "realtime_factor", "coverage"):
            r[k] = number(r.get(k))
        if not math.isfinite(r["sequence_s"]):
            r["sequence_s"] = r["realtime_factor"] * r["wall_s"]
        r["keyframe_reasons"] = r.get("keyframe_reasons") or ""
        # Absent in results.csv files written before dense clouds were part of a bench.
        r["dense_points"] = number(r.get("dense_points"))
        r["index"] = int(r["index"])
    rows.sort(key=lambda r: r["index"])
    return rows


def unique(values):
    return list(OrderedDict.fromkeys(values))


def mean_std(values):
    v = np.array([x for x in values if math.isfinite(x)], dtype=float)
    if v.size == 0:
        return math.nan, math.nan
    return float(v.mean()), float(v.std(ddof=1)) if v.size > 1 else 0.0


def safe(name):
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name)


class Index:
    def __init__(self, out):
        self.out = out
        self.lines = []

    def save(self, fig, name, section, caption):
        fig.savefig(os.path.join(self.out, name), dpi=DPI, bbox_inches="tight")
        plt.close(fig)
        self.lines.append(f"{name}\t{section}\t{caption}")

    def write(self):
        with open(os.path.join(self.out, "index.tsv"), "w") as f:
            f.write("\n".join(self.lines) + ("\n" if self.lines else ""))


def grouped_bars(ax, rows, datasets, configs, key, ylabel):
    width = 0.8 / max(len(configs), 1)
    x = np.arange(len(datasets))
    for i, config in enumerate(configs):
        means, stds = [], []
        for d in datasets:
            m, s = mean_std([r[key] for r in rows if r["dataset"] == d and r["config"] == config
                             and r["ok"]])
            means.append(m)
            stds.append(s)
        # A configuration without a successful run here (a peer that failed on every
        # dataset of this sensor) draws no bars: matplotlib cannot draw all-NaN error bars.
        if not any(math.isfinite(m) for m in means):
            continue
        stds = [s if math.isfinite(s) else 0.0 for s in stds]
        ax.bar(x + (i - (len(configs) - 1) / 2) * width, means, width, yerr=stds, capsize=3,
               label=config)
    ax.set_xticks(x)
    ax.set_xticklabels(datasets, rotation=20, ha="right")
    ax.set_ylabel(ylabel)
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize=8)


def per_sensor_bars(index, rows, key, ylabel, name, section, caption):
    sensors = unique(r["sensor"] for r in rows)
    fig, axes = plt.subplots(1, len(sensors), figsize=(max(6, 4 + 1.5 * len(sensors) * 2), 4.2),
                             squeeze=False)
    for ax, sensor in zip(axes[0], sensors):
        sub = [r for r in rows if r["sensor"] == sensor]
        datasets = unique(r["dataset"] for r in sub)
        configs = unique(r["config"] for r in sub)
        grouped_bars(ax, sub, datasets, configs, key, ylabel)
        ax.set_title(sensor)
    index.save(fig, name, section, caption)


def ate_cdf(index, rows):
    sensors = unique(r["sensor"] for r in rows)
    fig, axes = plt.subplots(1, len(sensors), figsize=(5.5 * len(sensors), 4), squeeze=False)
    for ax, sensor in zip(axes[0], sensors):
        sub = [r for r in rows if r["sensor"] == sensor]
        for config in unique(r["config"] for r in sub):
            v = np.sort([r["ate_m"] for r in sub if r["config"] == config and r["ok"]
                         and math.isfinite(r["ate_m"])])
            n_all = sum(1 for r in sub if r["config"] == config)
            if v.size == 0:
                continue
            # Failed runs never reach the top: the curve ends at (succeeded / all runs).
            ax.step(np.concatenate([[0], v]), np.arange(v.size + 1) / n_all, where="post",
                    label=f"{config} ({v.size}/{n_all})")
        finite = [r["ate_m"] for r in sub if r["ok"] and math.isfinite(r["ate_m"])
                  and r["ate_m"] > 0]
        # Diverging runs stretch a linear axis until the good runs are one vertical line.
        if finite and max(finite) > 20 * min(finite):
            ax.set_xscale("log")
        ax.set_xlabel("ATE RMSE [m]")
        ax.set_ylabel("fraction of runs")
        ax.set_ylim(0, 1.02)
        ax.set_title(sensor)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    index.save(fig, "ate_cdf.png", "accuracy",
               "Cumulative distribution of ATE over all runs and datasets per configuration "
               "(failed runs keep the curve below 1)")


def read_xyz(path, columns):
    if not os.path.exists(path):
        return None
    data = np.genfromtxt(path, delimiter=",", names=True)
    if data.size == 0:
        return None
    data = np.atleast_1d(data)
    return np.stack([data[c] for c in columns], axis=1)


def find_run(roots, run_id):
    for root in roots:
        d = os.path.join(root, run_id)
        if os.path.isdir(d):
            return d
    return None


def median_run(rows, config, roots):
    """The median-ATE run of a configuration and its folder (None when not found)."""
    runs = sorted((r for r in rows if r["config"] == config), key=lambda r: r["ate_m"])
    median = runs[(len(runs) - 1) // 2]
    return median, find_run(roots, median["run_id"])


def run_groups(rows):
    """(dataset, sensor, successful non-sweep runs, their configurations) per dataset and sensor."""
    for dataset in unique(r["dataset"] for r in rows):
        for sensor in unique(r["sensor"] for r in rows if r["dataset"] == dataset):
            sub = [r for r in rows if r["dataset"] == dataset and r["sensor"] == sensor
                   and r["ok"] and not r["sweep_param"]]
            configs = unique(r["config"] for r in sub)
            if configs:
                yield dataset, sensor, sub, configs


def trajectories(index, rows, roots):
    for dataset, sensor, sub, configs in run_groups(rows):
        fig, ax = plt.subplots(figsize=(6.5, 6))
        gt_drawn = False
        colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
        for i, config in enumerate(configs):
            median, d = median_run(sub, config, roots)
            if d is None:
                continue
            traj = read_xyz(os.path.join(d, "plot_trajectory.csv"),
                            ["gt_x", "gt_y", "est_x", "est_y"])
            if traj is None:
                continue
            if not gt_drawn:
                ax.plot(traj[:, 0], traj[:, 1], "k-", lw=2.0, alpha=0.6, label="ground truth")
                ax.plot(traj[0, 0], traj[0, 1], "ko", ms=6)
                gt_drawn = True
            color = colors[i % len(colors)]
            ax.plot(traj[:, 2], traj[:, 3], "-", color=color, lw=1.0,
                    label=f"{config} (ATE {median['ate_m']:.3f} m, "
                          f"{int(median['keyframes'])} KFs)")
            kf = read_xyz(os.path.join(d, "plot_keyframes.csv"), ["x", "y"])
            if kf is not None:
                ax.plot(kf[:, 0], kf[:, 1], "o", color=color, ms=3.5, mfc="none")
        if not gt_drawn:
            plt.close(fig)
            continue
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_title(f"{dataset} / {sensor}: top view (median-ATE run each)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="best")
        index.save(fig, f"traj_{safe(dataset)}_{safe(sensor)}.png", "trajectories",
                   f"{dataset}, {sensor}: ground truth (black) and estimates; circles are "
                   "keyframe positions")


def read_segments(run_dir):
    """A run's segment_errors.csv as {segment number (1 = shortest): translation errors in % of
    the length}, or None. The lengths are rpg's 10-50% of the sequence's path, so segment k
    covers the same share of every sequence and can be pooled over sequences."""
    path = os.path.join(run_dir, "segment_errors.csv")
    if not os.path.exists(path):
        return None
    with open(path, newline="") as f:
        table = list(csv.DictReader(f))
    lengths = sorted({float(r["length_m"]) for r in table})
    out = {}
    for r in table:
        out.setdefault(lengths.index(float(r["length_m"])) + 1, []).append(
            float(r["trans_percent"]))
    return out


def segment_boxes(index, rows, roots):
    """Per sensor: rpg's relative error over segment lengths, one box per configuration and
    segment (every pair of every successful run of every sequence)."""
    for sensor in unique(r["sensor"] for r in rows):
        sub = [r for r in rows if r["sensor"] == sensor and r["ok"] and not r["sweep_param"]]
        configs = unique(r["config"] for r in sub)
        pooled = {c: {} for c in configs}
        for r in sub:
            d = find_run(roots, r["run_id"])
            segments = read_segments(d) if d else None
            for k, values in (segments or {}).items():
                pooled[r["config"]].setdefault(k, []).extend(values)
        ks = sorted({k for c in configs for k in pooled[c]})
        if not ks:
            continue
        fig, ax = plt.subplots(figsize=(max(7, 1.4 * len(ks) * max(1, len(configs)) / 2 + 3),
                                        4.5))
        colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
        width = 0.8 / len(configs)
        for i, config in enumerate(configs):
            data = [pooled[config].get(k) or [math.nan] for k in ks]
            pos = [k + (i - (len(configs) - 1) / 2) * width for k in ks]
            box = ax.boxplot(data, positions=pos, widths=width * 0.9, patch_artist=True,
                             showfliers=False, manage_ticks=False)
            for patch in box["boxes"]:
                patch.set_facecolor(colors[i % len(colors)])
                patch.set_alpha(0.6)
            ax.plot([], [], color=colors[i % len(colors)], lw=6, alpha=0.6, label=config)
        ax.set_xticks(ks)
        ax.set_xticklabels([f"{10 * k}%" for k in ks])
        ax.set_xlabel("segment length (share of the sequence's path, rpg_trajectory_evaluation)")
        ax.set_ylabel("translation error [% of the length]")
        ax.grid(True, axis="y", alpha=0.3)
        ax.legend(fontsize=8)
        ax.set_title(f"{sensor}: relative error over segment lengths, all sequences")
        index.save(fig, f"segments_{safe(sensor)}.png", "accuracy",
                   f"{sensor}: relative translation error over segments of 10-50% of each "
                   "sequence's path (rpg_trajectory_evaluation), pooled over sequences and runs; "
                   "one box per configuration (whiskers 1.5 IQR, outliers not drawn)")


def online_calibration(index, rows, roots):
    """Per dataset and sensor, every online-calibration run's estimates over the flight
    (stats.json calibration.history, applied adjustments): time offset, camera-IMU rotation change,
    cam0 fx change, the disparity offset change (cam0.cx - cam1.cx) against the file and the
    gyro's scale-factor error (the largest axis, signed)."""
    panels = [("time_offset", "time offset [ms]", None),
              ("imu_rotation", "camera-IMU rotation change [deg]", None),
              ("cam0.fx", "cam0 fx - file [px]", None),
              ("disparity", "(cam0.cx - cam1.cx) - file [px]", None),
              ("gyro_scale", "gyro scale error, largest axis [%]", None)]
    for dataset, sensor, sub, configs in run_groups(rows):
        series = []
        for r in sub:
            d = find_run(roots, r["run_id"])
            if d is None or not os.path.exists(os.path.join(d, "stats.json")):
                continue
            with open(os.path.join(d, "stats.json")) as f:
                c = json.load(f).get("calibration") or {}
            if c.get("mode") != "online":
                continue
            file = {p["name"]: p["file"] for p in c.get("parameters", [])}
            steps = [h for h in c.get("history", []) if h.get("applied")]
            if not steps:
                continue
            t = [h["span_s"] for h in steps]

            def value(e, key):
                if key == "imu_rotation":
                    return math.sqrt(sum(e.get(f"imu.r{a}", 0.0) ** 2 for a in "xyz"))
                if key == "disparity":
                    if "cam1.cx" not in e:
                        return float("nan")
                    return (e["cam0.cx"] - e["cam1.cx"]) - (file["cam0.cx"] - file["cam1.cx"])
                if key == "cam0.fx":
                    return e.get(key, float("nan")) - file.get(key, 0.0)
                if key == "gyro_scale":
                    k = [e[f"gyro.s{a}"] for a in "xyz" if f"gyro.s{a}" in e]
                    return max(k, key=abs) if k else float("nan")
                return e.get(key, float("nan"))
            series.append((f"{r['config']} seed {r['seed']}",
                           t, {k: [value(h["estimate"], k) for h in steps] for k, _, _ in panels}))
        if not series:
            continue
        fig, axes = plt.subplots(1, len(panels), figsize=(18, 3.4))
        for ax, (key, label, _) in zip(axes, panels):
            for name, t, values in series:
                ax.plot(t, values[key], marker="o", ms=3, label=name)
            ax.set_title(label, fontsize=9)
            ax.set_xlabel("map span at the adjustment [s]")
            ax.grid(alpha=0.3)
        axes[0].legend(fontsize=7)
        index.save(fig, f"calibration_{safe(dataset)}_{safe(sensor)}.png", "calibration",
                   f"{dataset}, {sensor}: the online calibration estimates of each run over the "
                   "flight (applied adjustments)")


def sweeps(index, rows):
    for param in unique(r["sweep_param"] for r in rows if r["sweep_param"]):
        sub = [r for r in rows if r["sweep_param"] == param]
        dense = any(math.isfinite(r["dense_points"]) for r in sub if r["ok"])
        if dense:
            fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(16, 4))
        else:
            fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4))
        flat = []  # lines on which no value changed keyframes or ATE (said in the caption)
        for dataset in unique(r["dataset"] for r in sub):
            for sensor in unique(r["sensor"] for r in sub if r["dataset"] == dataset):
                for base in unique(r["config"].split("@")[0] for r in sub):
                    pts = [r for r in sub if r["dataset"] == dataset and r["sensor"] == sensor
                           and r["config"].split("@")[0] == base]
                    values = sorted(set(r["sweep_value"] for r in pts))
                    ate = [mean_std([r["ate_m"] for r in pts if r["sweep_value"] == v
                                     and r["ok"]]) for v in values]
                    kfs = [mean_std([r["keyframes"] for r in pts if r["sweep_value"] == v
                                     and r["ok"]]) for v in values]
                    label = f"{dataset}/{sensor}/{base}"
                    if len(values) > 1 and len({(a, k) for a, k in zip(ate, kfs)}) == 1:
                        flat.append(label)
                    a1.errorbar(values, [m for m, _ in ate], yerr=[s for _, s in ate],
                                marker="o", capsize=3, label=label)
                    a2.errorbar(values, [m for m, _ in kfs], yerr=[s for _, s in kfs],
                                marker="s", capsize=3, label=label)
                    if dense:
                        equation13(a3, values, [m for m, _ in ate],
                                   [mean_std([r["dense_points"] for r in pts
                                              if r["sweep_value"] == v and r["ok"]])[0]
                                    for v in values], label)
        a1.set_xlabel(param)
        a1.set_ylabel("ATE RMSE [m] (mean ± std)")
        a2.set_xlabel(param)
        a2.set_ylabel("keyframes (mean ± std)")
        axes = (a1, a2)
        if dense:
            a3.set_xlabel(param)
            a3.set_ylabel("normalised dense points − normalised ATE")
            a3.set_title("PKS paper Eq. 13 (star: best value)", fontsize=9)
            axes = (a1, a2, a3)
        for a in axes:
            a.grid(alpha=0.3)
            a.legend(fontsize=8)
        index.save(fig, f"sweep_{safe(param)}.png", "sweeps",
                   f"Sweep of {param}: accuracy and keyframe count per value"
                   + (", and the Eq. 13 score from the dense clouds" if dense else "")
                   + (f". No value of {param} changed the runs of {', '.join(flat)} (the same "
                      f"keyframes and ATE at every value): the parameter did not act there"
                      if flat else ""))


def equal_budget(index, rows):
    """ATE against keyframes per second and against local-mapping CPU time: every configuration
    (sweep values included) as one point per dataset, a selector's sweep joined by a line, so a
    better selection is not confused with more keyframes."""
    if not any(r["sweep_param"] for r in rows):
        return
    for sensor in unique(r["sensor"] for r in rows):
        sub = [r for r in rows if r["sensor"] == sensor and r["ok"]]
        datasets = unique(r["dataset"] for r in sub)
        if not datasets:
            continue
        fig, axes = plt.subplots(len(datasets), 2, figsize=(11, 3.6 * len(datasets)),
                                 squeeze=False)
        colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
        for row, dataset in zip(axes, datasets):
            pts = [r for r in sub if r["dataset"] == dataset]
            bases = unique(r["config"].split("@")[0] for r in pts)
            for i, base in enumerate(bases):
                color = colors[i % len(colors)]
                group = [r for r in pts if r["config"].split("@")[0] == base]
                configs = unique(r["config"] for r in group)
                xs_kf, xs_cpu, ys = [], [], []
                for config in configs:
                    runs = [r for r in group if r["config"] == config]
                    kfps = [r["keyframes"] / r["sequence_s"] for r in runs
                            if math.isfinite(r["sequence_s"]) and r["sequence_s"] > 0]
                    cpu = [r["mapping_cpu_s"] for r in runs]
                    xs_kf.append(mean_std(kfps)[0])
                    xs_cpu.append(mean_std(cpu)[0])
                    # The median: one run that lost tracking must not move a whole point.
                    ate = [r["ate_m"] for r in runs if math.isfinite(r["ate_m"])]
                    ys.append(float(np.median(ate)) if ate else math.nan)
                for ax, xs in ((row[0], xs_kf), (row[1], xs_cpu)):
                    order = sorted((x, y) for x, y in zip(xs, ys)
                                   if math.isfinite(x) and math.isfinite(y))
                    if not order:
                        continue
                    ax.plot([x for x, _ in order], [y for _, y in order], "-o", color=color,
                            ms=4, label=base)
            row[0].set_xlabel("keyframes per second (final map)")
            row[1].set_xlabel("local-mapping CPU time [s]")
            for ax in row:
                ax.set_ylabel("ATE RMSE [m] (median of runs)")
                ax.set_title(f"{dataset} / {sensor}", fontsize=9)
                ax.grid(alpha=0.3)
                ax.legend(fontsize=7)
        fig.tight_layout()
        index.save(fig, f"equal_budget_{safe(sensor)}.png", "budget",
                   f"{sensor}: median ATE of the successful runs against keyframes per second "
                   "(mean over runs) and against local-mapping CPU time; each selector's sweep is "
                   "one line (compare selectors at equal x)")


def per_sequence_cdf(index, rows):
    """The PKS paper's per-sequence plot: each configuration's runs sorted by ATE."""
    for sensor in unique(r["sensor"] for r in rows):
        sub = [r for r in rows if r["sensor"] == sensor]
        datasets = unique(r["dataset"] for r in sub)
        # The last panel pools every sequence (the paper's per-sequence plot beside the pooled).
        panels = datasets + ([None] if len(datasets) > 1 else [])
        cols = min(3, len(panels))
        rows_n = math.ceil(len(panels) / cols)
        fig, axes = plt.subplots(rows_n, cols, figsize=(4.6 * cols, 3.4 * rows_n), squeeze=False)
        for ax, dataset in zip(axes.flat, panels):
            for config in unique(r["config"] for r in sub
                                 if dataset is None or r["dataset"] == dataset):
                runs = [r for r in sub if r["config"] == config
                        and (dataset is None or r["dataset"] == dataset)]
                v = np.sort([r["ate_m"] for r in runs if r["ok"] and math.isfinite(r["ate_m"])])
                if v.size == 0:
                    continue
                ax.plot(np.arange(1, v.size + 1), np.cumsum(v), "-o", ms=3,
                        label=f"{config} ({v.size}/{len(runs)})")
            ax.set_title(dataset if dataset is not None
                         else f"all {len(datasets)} sequences pooled", fontsize=9)
            ax.set_xlabel("runs (sorted by ATE)")
            ax.set_ylabel("cumulative ATE [m]")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
        for ax in list(axes.flat)[len(panels):]:
            ax.axis("off")
        fig.tight_layout()
        index.save(fig, f"ate_cumulative_{safe(sensor)}.png", "accuracy",
                   f"{sensor}: cumulative ATE over each configuration's runs sorted by ATE, per "
                   "sequence, as the PKS paper plots it, and pooled over the sequences in the last "
                   "panel (failed runs are left out; n/N in the legend)")


def keyframe_views(index, rows, roots):
    """Top views with the keyframes of each configuration's median-ATE run, one panel each."""
    for dataset, sensor, sub, configs in run_groups(rows):
        fig, axes = plt.subplots(1, len(configs), figsize=(3.6 * len(configs), 3.8),
                                 squeeze=False)
        drawn = 0
        for ax, config in zip(axes[0], configs):
            _, d = median_run(sub, config, roots)
            traj = read_xyz(os.path.join(d, "plot_trajectory.csv"),
                            ["gt_x", "gt_y"]) if d else None
            kf = read_xyz(os.path.join(d, "plot_keyframes.csv"), ["x", "y"]) if d else None
            if traj is None:
                ax.axis("off")
                continue
            ax.plot(traj[:, 0], traj[:, 1], "-", color="0.6", lw=1)
            if kf is not None:
                ax.plot(kf[:, 0], kf[:, 1], "o", ms=2.5, color="C3")
            ax.set_aspect("equal", adjustable="datalim")
            ax.set_title(f"{config}: {0 if kf is None else len(kf)} KFs", fontsize=9)
            ax.tick_params(labelsize=7)
            drawn += 1
        if not drawn:
            plt.close(fig)
            continue
        index.save(fig, f"keyframes_{safe(dataset)}_{safe(sensor)}.png", "trajectories",
                   f"{dataset}, {sensor}: keyframe positions (red) of each configuration's "
                   "median-ATE run over the ground-truth path (grey)")


def reason_shares(index, rows):
    """Which rule created the keyframes: share per configuration (a keyframe counts for every
    rule its reason names, e.g. forced+imu)."""
    rows = [r for r in rows if r["keyframe_reasons"] and not r["sweep_param"]]
    if not rows:
        return
    sensors = unique(r["sensor"] for r in rows)
    fig, axes = plt.subplots(1, len(sensors), figsize=(6 * len(sensors), 4), squeeze=False)
    for ax, sensor in zip(axes[0], sensors):
        sub = [r for r in rows if r["sensor"] == sensor]
        configs = unique(r["config"] for r in sub)
        counts = {c: {} for c in configs}
        for r in sub:
            for item in r["keyframe_reasons"].split():
                reason, _, n = item.rpartition("=")
                for rule in reason.split(";")[0].split("+"):
                    counts[r["config"]][rule] = counts[r["config"]].get(rule, 0) + number(n)
        rules = unique(rule for c in configs for rule in counts[c])
        bottom = np.zeros(len(configs))
        for rule in rules:
            share = np.array([counts[c].get(rule, 0) / max(1, sum(counts[c].values()))
                              for c in configs])
            ax.bar(range(len(configs)), share, bottom=bottom, label=rule)
            bottom += share
        ax.set_xticks(range(len(configs)))
        ax.set_xticklabels(configs, rotation=25, ha="right", fontsize=8)
        ax.set_ylabel("share of rule mentions")
        ax.set_title(sensor)
        ax.legend(fontsize=7, ncol=2)
    index.save(fig, "keyframe_reasons.png", "keyframes",
               "Which rule created the keyframes, per configuration (all runs)")


def statistics_fragments(out, results_path):
    """The Statistics section (bench_statistics.py) as Markdown and HTML fragments."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import bench_statistics  # noqa: E402 (scipy: only needed here)
    rows = bench_statistics.read_rows(results_path)
    if not rows:
        return
    mixed = bench_statistics.pooled_builds(rows)
    if mixed:  # the report says why, instead of tests over runs of different programs
        text = (f"Not computed: {mixed}. Run `bench_statistics.py --pool-builds` to analyse "
                "them together anyway.\n")
        with open(os.path.join(out, "statistics.md"), "w") as f:
            f.write(text)
        with open(os.path.join(out, "statistics.html"), "w") as f:
            f.write(f"<p>{html.escape(text)}</p>\n")
        return
    result = bench_statistics.analyse(rows)
    with open(os.path.join(out, "statistics.md"), "w") as f:
        f.write(bench_statistics.markdown(result))
    with open(os.path.join(out, "statistics.html"), "w") as f:
        f.write(bench_statistics.html_fragment(result))
    with open(os.path.join(out, "statistics.json"), "w") as f:
        json.dump(result, f, indent=1, default=float)


def equation13(axis, values, ate, dense, label):
    """Plots min-max normalised density minus normalised ATE; marks the argmax."""
    pts = [(v, a, d) for v, a, d in zip(values, ate, dense)
           if math.isfinite(a) and math.isfinite(d)]
    if len(pts) < 2:
        return

    def norm(x, xs):
        lo, hi = min(xs), max(xs)
        return (x - lo) / (hi - lo) if hi > lo else 0.0

    a_all = [a for _, a, _ in pts]
    d_all = [d for _, _, d in pts]
    score = [norm(d, d_all) - norm(a, a_all) for _, a, d in pts]
    xs = [v for v, _, _ in pts]
    line, = axis.plot(xs, score, marker="o", label=label)
    best = int(np.argmax(score))
    axis.plot([xs[best]], [score[best]], marker="*", markersize=14, color=line.get_color())


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--results", required=True)
    p.add_argument("--runs", action="append", default=[], help="folder of run folders")
    p.add_argument("--out", required=True)
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    rows = read_results(a.results)
    index = Index(a.out)
    # Plots need at least one finished run; a suite where every run failed gets its tables only.
    if any(r["ok"] for r in rows):
        main_rows = [r for r in rows if not r["sweep_param"]] or rows
        per_sensor_bars(index, main_rows, "ate_m", "ATE RMSE [m]", "ate_bars.png", "accuracy",
                        "ATE per sequence: mean over runs, error bars one standard deviation")
        ate_cdf(index, main_rows)
        per_sequence_cdf(index, main_rows)
        segment_boxes(index, rows, a.runs)
        trajectories(index, rows, a.runs)
        keyframe_views(index, rows, a.runs)
        reason_shares(index, rows)
        per_sensor_bars(index, main_rows, "keyframes", "keyframes in the final map",
                        "keyframes.png", "keyframes", "Keyframes per sequence (mean ± std)")
        per_sensor_bars(index, main_rows, "median_tracking_ms", "median tracking time [ms]",
                        "tracking_time.png", "keyframes",
                        "Median per-frame tracking time (mean ± std over runs)")
        sweeps(index, rows)
        online_calibration(index, rows, a.runs)
        equal_budget(index, rows)
        statistics_fragments(a.out, a.results)
    index.write()
    print(f"plots: {len(index.lines)} PNGs in {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
