#!/usr/bin/env python3
"""The calibration estimates of a run over time (its stats.json "calibration" section).

    python3 evaluation/calibration_plot.py RUN/stats.json OUT.png [--title TEXT]

Six panels against the data time of each adjustment: intrinsics (estimate - file, px), the
rotation of the stereo and camera-IMU extrinsics (deg), their translation (mm), the camera-IMU
time offset (ms), the gyro's and the accelerometer's per-axis scale-factor errors (%) and the
accelerometer's axis misalignment (deg). The final estimate is drawn at the end with its 1-sigma bar when
the run computed sigmas. Used by `pkslam calibrate` (DIR/calibration_history.png), the bench
report and docs/calibration.md.
"""
import argparse
import json
import sys


def groups(name):
    if name.startswith("cam") and name.split(".")[1] in ("fx", "fy", "cx", "cy"):
        return 0
    if name.startswith(("stereo.r", "imu.r")):
        return 1
    if name.startswith(("stereo.t", "imu.t")):
        return 2
    if name == "time_offset":
        return 3
    if name.startswith(("gyro.s", "accel.s")):
        return 4
    if name.startswith("accel.m"):
        return 5
    return None  # distortion: too small to share an axis with pixels


TITLES = ["intrinsics: estimate - file [px]", "extrinsic rotation change [deg]",
          "extrinsic translation change [mm]", "camera-IMU time offset [ms]",
          "IMU scale-factor error: estimate - file [%]",
          "accelerometer misalignment: estimate - file [deg]"]


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("stats")
    parser.add_argument("out")
    parser.add_argument("--title", default="")
    args = parser.parse_args(argv[1:])
    with open(args.stats) as f:
        calibration = json.load(f).get("calibration")
    if not calibration or calibration.get("mode") != "online":
        print(f"{args.stats}: no online calibration to plot", file=sys.stderr)
        return 1
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    final = {p["name"]: p for p in calibration["parameters"]}
    history = [h for h in calibration["history"] if h.get("applied")]
    fig, grid = plt.subplots(2, 3, figsize=(15, 7), sharex=True)
    axes = grid.ravel()
    t_end = max([h["span_s"] for h in history] + [1.0]) * 1.08
    for name, p in final.items():
        g = groups(name)
        if g is None or not p.get("free"):
            continue
        ax = axes[g]
        ts = [h["span_s"] for h in history if name in h["estimate"]]
        base = p["file"] if g in (0, 4, 5) else 0.0
        ys = [h["estimate"][name] - base for h in history if name in h["estimate"]]
        line, = ax.plot(ts, ys, marker="o", ms=3, label=name)
        ax.errorbar([t_end], [p["estimate"] - base], yerr=[p.get("sigma", 0.0)], fmt="s",
                    color=line.get_color(), capsize=3)
    for ax, title in zip(axes, TITLES):
        ax.set_title(title, fontsize=10)
        ax.axhline(0.0, color="grey", lw=0.8)
        ax.grid(alpha=0.3)
        if any(not line.get_label().startswith("_") for line in ax.lines):
            ax.legend(fontsize=7, ncol=2)
    for ax in axes[3:]:  # the bottom row
        ax.set_xlabel("data time of the map at the adjustment [s] (square: final, 1 sigma)")
    fig.suptitle(args.title or "calibration estimates while mapping", fontsize=11)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
