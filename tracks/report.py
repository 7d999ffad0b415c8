#!/usr/bin/python3
"""report.html for `pkslam tracks reconstruct` (the thesis's figures, seed 002): reprojection-error
histograms at chosen frames, the mean reprojection error per frame, the trajectory against truth
(top view, after Sim(3) alignment) and the map, plus a table from stats.json.

  /usr/bin/python3 tracks/report.py --run OUT [--truth TRACKS_DIR]

Reads OUT/stats.json, frames.csv, reprojection_errors.csv, trajectory_aligned.txt (or
trajectory.txt without truth) and map.ply's header only; writes OUT/report.html and OUT/*.png.
"""

import argparse
import csv
import html
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_tum(path):
    rows = []
    with open(path) as f:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            v = [float(x) for x in line.split()]
            rows.append(v[:4])
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", required=True)
    ap.add_argument("--truth", default="")
    a = ap.parse_args()
    run = a.run
    stats = json.load(open(os.path.join(run, "stats.json")))
    frames = list(csv.DictReader(open(os.path.join(run, "frames.csv"))))
    errors = {}
    with open(os.path.join(run, "reprojection_errors.csv")) as f:
        for row in csv.DictReader(f):
            errors.setdefault(int(row["frame"]), []).append(float(row["error_px"]))
    figures = []

    # Histograms at the chosen frames (the thesis's Fig. 6, 11-13).
    for frame in stats.get("histogram_frames", []):
        e = errors.get(frame)
        if not e:
            figures.append((None, f"Frame {frame}: not tracked or no mapped observation."))
            continue
        fig, ax = plt.subplots(figsize=(5, 3.2))
        top = max(1.0, max(e))
        ax.hist(e, bins=40, range=(0, top), color="#3070b0")
        ax.set_xlabel("reprojection error (px)")
        ax.set_ylabel("points")
        mean = sum(e) / len(e)
        ax.set_title(f"frame {frame} (counted from 0): {len(e)} points, mean {mean:.2f} px")
        fig.tight_layout()
        name = f"histogram_frame_{frame}.png"
        fig.savefig(os.path.join(run, name), dpi=100)
        plt.close(fig)
        figures.append((name, f"Reprojection errors at frame {frame} (the thesis's frame "
                              f"{frame + 1}, counted from 1)."))

    # Mean reprojection error per frame (the thesis's Fig. 14), keyframes marked.
    xs, ys, kx, ky = [], [], [], []
    for row in frames:
        m = row["mean_error_px"]
        if m in ("", "nan"):
            continue
        xs.append(int(row["frame"]))
        ys.append(float(m))
        if row["keyframe"] == "1":
            kx.append(xs[-1])
            ky.append(ys[-1])
    if xs:
        fig, ax = plt.subplots(figsize=(7, 3.2))
        ax.plot(xs, ys, "-", color="#3070b0", label="mean per frame")
        ax.plot(kx, ky, "o", color="#d04020", label="keyframes")
        ax.set_xlabel("frame")
        ax.set_ylabel("mean reprojection error (px)")
        ax.set_ylim(bottom=0)
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(run, "mean_error_per_frame.png"), dpi=100)
        plt.close(fig)
        figures.append(("mean_error_per_frame.png", "Mean reprojection error per frame."))

    # Trajectory top view (x-y and x-z) against truth.
    aligned = os.path.join(run, "trajectory_aligned.txt")
    est = read_tum(aligned if os.path.exists(aligned) else os.path.join(run, "trajectory.txt"))
    truth = []
    if a.truth and os.path.exists(os.path.join(a.truth, "truth_trajectory.txt")):
        truth = read_tum(os.path.join(a.truth, "truth_trajectory.txt"))
    if est:
        fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
        for ax, (i, j, label) in zip(axes, [(1, 2, "x-y"), (1, 3, "x-z")]):
            if truth:
                ax.plot([p[i] for p in truth], [p[j] for p in truth], "-", color="#888888",
                        label="truth")
            ax.plot([p[i] for p in est], [p[j] for p in est], "-", color="#3070b0",
                    label="estimate" + (" (Sim3-aligned)" if truth else ""))
            ax.set_title(label)
            ax.set_aspect("equal", adjustable="datalim")
            ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(run, "trajectory.png"), dpi=100)
        plt.close(fig)
        figures.append(("trajectory.png", "Camera trajectory" +
                        (" against truth after Sim(3) alignment." if truth else ".")))

    acc = stats.get("accuracy")
    init = stats["init"]
    rows = [
        ("frames tracked", f"{stats['tracked_frames']} of {stats['frames']}"),
        ("keyframes", f"{stats['keyframes']} "
                      f"({', '.join(f'{k}: {v}' for k, v in stats['keyframe_reasons'].items())})"),
        ("map points", f"{stats['map_points']} of {stats['tracks']} tracks"),
        ("initial pair", f"frames {init['first']} and {init['second']}, median parallax "
                         f"{init['median_parallax_deg']:.2f} deg, {init['triangulated']} points "
                         f"({init['pairs_refused']} earlier pairs refused)"),
        ("reprojection error (px)",
         "mean {mean:.3f}, median {median:.3f}, max {max:.2f}".format(**stats["reprojection_px"])
         if "reprojection_px" in stats else "-"),
        ("run time (s)", "total {total:.3f} (init {init:.3f}, tracking {tracking:.3f}, "
                         "mapping {mapping:.3f})".format(**stats["seconds"])),
    ]
    if acc:
        rows.append(("ATE after Sim(3)", f"rmse {acc['ate_sim3']['rmse']:.4g}, mean "
                                         f"{acc['ate_sim3']['mean']:.4g} (truth units; "
                                         f"{acc['pairs']} poses)"))
        if acc.get("map_error"):
            rows.append(("map point error", f"rmse {acc['map_error']['rmse']:.4g}, median "
                                            f"{acc['map_error']['median']:.4g} (truth units; "
                                            f"median depth {acc['median_truth_depth']:.4g})"))
    out = ["<!DOCTYPE html><html><head><meta charset='utf-8'><title>pkslam tracks report</title>",
           "<style>body{font-family:sans-serif;max-width:60em;margin:1em auto;padding:0 1em}"
           "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:3px 8px;"
           "text-align:left}img{max-width:100%}figcaption{color:#555;font-style:italic}"
           "</style></head><body>",
           "<h1>Reconstruction from tracks</h1><table>"]
    for k, v in rows:
        out.append(f"<tr><th>{html.escape(k)}</th><td>{html.escape(v)}</td></tr>")
    out.append("</table>")
    for name, caption in figures:
        if name:
            out.append(f"<figure><img src='{name}' alt='{html.escape(caption)}'>"
                       f"<figcaption>{html.escape(caption)}</figcaption></figure>")
        else:
            out.append(f"<p>{html.escape(caption)}</p>")
    out.append("</body></html>")
    with open(os.path.join(run, "report.html"), "w") as f:
        f.write("\n".join(out) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
