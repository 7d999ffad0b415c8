#!/usr/bin/python3
"""How smooth the EuRoC ground truth is, and up to which frequency it may be differentiated.

For each TUM-format file (t x y z qx qy qz qw) in --gt-dir:
  * sample rate, gaps (dt > 1.5x median), timestamp jitter;
  * high-frequency noise: residual of a quintic Savitzky-Golay fit over --window s, positions
    (mm, RMS and robust 1.4826*MAD) and orientations (mrad), plus jumps (> 10x robust);
  * PSD (Welch) of the twice-differentiated position (acceleration), in bands, and its plot;
  * max and 99th percentile of |acceleration| (m/s^2) and |angular rate| (deg/s) after a
    zero-phase 4th-order Butterworth low-pass at 5, 10, 20, 40 Hz;
  * the 50 ms periodic artefact: mean high-pass |acc| per sample phase (index mod 10) and the
    20 Hz spectral line over the floor; the spectral slope above 20 Hz (4 = white position noise);
  * a recommended smoothing cutoff: knee = lowest frequency where the (1 Hz-smoothed)
    acceleration PSD falls below 2x its 8-18 Hz floor (rigid-body motion has ended there);
    recommended = ceil(2 x knee), capped where a 4th-order low-pass pushes the 20 Hz line
    down to the floor.

  /usr/bin/python3 evaluation/studies/realism/gt_smoothness.py [--gt-dir DIR] [--out DIR]
Writes gt_smoothness.json and gt_acceleration_psd.png into --out (default: this folder).
"""
import argparse
import json
import math
from pathlib import Path

import numpy as np
from scipy import signal
from scipy.spatial.transform import Rotation

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
DEFAULT_GT = REPO / "../shared/data/euroc/groundtruth"
FILES = ("MH_01_easy", "MH_02_easy", "V1_01_easy_original", "V1_02_medium", "V2_01_easy")
CUTOFFS = (5, 10, 20, 40)


def lowpass(x, fc, fs):
    return signal.sosfiltfilt(signal.butter(4, fc, fs=fs, output="sos"), x, axis=0)


def acceleration(p, dt):
    """Second central difference, same length as p (ends repeated)."""
    a = (p[2:] - 2 * p[1:-1] + p[:-2]) / dt ** 2
    return np.vstack([a[:1], a, a[-1:]])


def angular_rate(quats, dt):
    """Body angular rate (rad/s) from xyzw quaternions, central (mean of the two half steps)."""
    r = Rotation.from_quat(quats)
    w = (r[:-1].inv() * r[1:]).as_rotvec() / dt
    return np.vstack([w[:1], (w[:-1] + w[1:]) / 2, w[-1:]])


def motion_cutoff(acc, fs):
    """(knee_hz, recommended_hz, floor, line20_over_floor) from the acceleration PSD."""
    f, P = signal.welch(acc, fs=fs, nperseg=2048, axis=0)
    P = P.sum(1)
    floor = np.median(P[(f >= 8) & (f <= 18)])
    smooth = np.convolve(P, np.ones(11) / 11, "same")
    knee = float(f[np.nonzero((f > 0.5) & (smooth < 2 * floor))[0][0]])
    line = float(P[np.abs(f - 20) < 0.3].max() / floor)
    comb_safe = 20 / max(line, 1) ** (1 / 8)
    return knee, float(min(math.ceil(2 * knee), math.floor(comb_safe))), float(floor), line


def savgol_noise(p, quats, n):
    """Residuals of a quintic Savitzky-Golay fit: positions (m, per axis) and angles (rad)."""
    pres = p - signal.savgol_filter(p, n, 5, axis=0)
    flips = np.sign(np.einsum("ij,ij->i", quats[1:], quats[:-1]))  # sign continuity first
    q = quats * np.r_[1, np.cumprod(flips)][:, None]
    qs = signal.savgol_filter(q, n, 5, axis=0)
    ang = (Rotation.from_quat(qs).inv() * Rotation.from_quat(q)).magnitude()
    return pres, ang


def robust(x):
    return 1.4826 * np.median(np.abs(x - np.median(x)))


def analyse(path, window):
    gt = np.loadtxt(path)
    t, p, q = gt[:, 0], gt[:, 1:4], gt[:, 4:8]
    dts = np.diff(t)
    dt = float(np.median(dts))
    fs = 1 / dt
    out = {"samples": len(t), "duration_s": float(t[-1] - t[0]), "rate_hz": fs,
           "gaps": int((dts > 1.5 * dt).sum()), "max_dt_s": float(dts.max()),
           "dt_jitter_us": float(1e6 * np.abs(dts - dt).max())}
    n = int(round(window * fs)) | 1
    pres, ang = savgol_noise(p, q, n)
    r3 = np.linalg.norm(pres, axis=1)
    out["savgol_window_samples"] = n
    out["pos_noise_rms_mm"] = float(1e3 * np.sqrt(np.mean(r3 ** 2)))
    out["pos_noise_robust_mm_xyz"] = (1e3 * np.array([robust(c) for c in pres.T])).round(4).tolist()
    bad = np.nonzero(r3 > 10 * np.sqrt(3) * max(robust(c) for c in pres.T))[0]
    events = bad[np.r_[True, np.diff(bad) > n]] if len(bad) else bad  # one event per window
    out["pos_jump_events"] = int(len(events))
    out["pos_jump_times_s"] = (t[events] - t[0]).round(2).tolist()[:20]
    out["pos_jump_max_residual_mm"] = float(1e3 * r3[bad].max()) if len(bad) else 0.0
    out["rot_noise_rms_mrad"] = float(1e3 * np.sqrt(np.mean(ang ** 2)))
    out["rot_noise_median_mrad"] = float(1e3 * np.median(ang))
    acc, w = acceleration(p, dt), angular_rate(q, dt)
    f, P = signal.welch(acc, fs=fs, nperseg=2048, axis=0)
    P = P.sum(1)
    comb = np.min(np.abs(f[:, None] - np.arange(20, fs / 2 + 1, 20)[None]), 1) < 1.0
    bands = ((0, 1), (1, 2), (2, 3), (3, 5), (5, 8), (8, 12), (12, 18),
             (21, 39), (41, 59), (61, 79), (81, 99))
    out["acc_psd_bands"] = {f"{lo}-{hi}Hz": float(P[(f >= lo) & (f < hi) & ~comb].mean())
                            for lo, hi in bands}
    out["acc_psd_lines"] = {f"{k}Hz": float(P[np.abs(f - k) < 0.3].max()) for k in (20, 40, 60, 80)}
    hf = (f > 22) & (f < 98) & ~comb
    out["acc_psd_slope_above_20hz"] = float(np.polyfit(np.log(f[hf]), np.log(P[hf]), 1)[0])
    hp = np.linalg.norm(acc - lowpass(acc, 10, fs), axis=1)
    phase = np.array([hp[i::10].mean() for i in range(10)])
    out["hp_acc_by_sample_phase"] = phase.round(3).tolist()
    out["periodic_50ms_ratio"] = float(phase.max() / np.median(phase))
    out["lowpass"] = {f"{fc}Hz": extremes(lowpass(acc, fc, fs), lowpass(w, fc, fs), t) for fc in CUTOFFS}
    knee, rec, floor, line = motion_cutoff(acc, fs)
    out.update({"knee_hz": knee, "psd_floor_8_18hz": floor, "line20_over_floor": line,
                "recommended_cutoff_hz": rec,
                "at_recommended": extremes(lowpass(acc, rec, fs), lowpass(w, rec, fs), t)})
    return out, (f, P)


def extremes(acc, rate, t):
    an, wn = np.linalg.norm(acc, axis=1), np.degrees(np.linalg.norm(rate, axis=1))
    return {"acc_p99": float(np.percentile(an, 99)), "acc_max": float(an.max()),
            "acc_max_at_s": float(t[np.argmax(an)] - t[0]),
            "rate_p99_deg_s": float(np.percentile(wn, 99)), "rate_max_deg_s": float(wn.max())}


def report(name, r):
    print(f"{name}: {r['samples']} samples, {r['duration_s']:.1f} s, {r['rate_hz']:.1f} Hz, "
          f"gaps {r['gaps']}, dt jitter {r['dt_jitter_us']:.2f} us")
    print(f"  noise (SG quintic, {r['savgol_window_samples']} samples): pos {r['pos_noise_rms_mm']:.3f}"
          f" mm rms, robust xyz {r['pos_noise_robust_mm_xyz']} mm; rot {r['rot_noise_rms_mrad']:.3f}"
          f" mrad rms, median {r['rot_noise_median_mrad']:.3f} mrad")
    print(f"  {r['pos_jump_events']} position jumps (max residual {r['pos_jump_max_residual_mm']:.1f}"
          f" mm) at {r['pos_jump_times_s'][:8]} s")
    print("  acc PSD (m/s2)^2/Hz: " + " ".join(f"{k} {v:.1e}" for k, v in r["acc_psd_bands"].items()))
    print("  lines: " + " ".join(f"{k} {v:.1e}" for k, v in r["acc_psd_lines"].items())
          + f"; slope above 20 Hz {r['acc_psd_slope_above_20hz']:.1f}; 50 ms periodic ratio "
          f"{r['periodic_50ms_ratio']:.1f} (by phase {r['hp_acc_by_sample_phase']})")
    for k, v in r["lowpass"].items():
        print(f"  low-pass {k:>4}: |acc| p99 {v['acc_p99']:.2f} max {v['acc_max']:.2f} m/s2 "
              f"(at {v['acc_max_at_s']:.1f} s), |rate| p99 {v['rate_p99_deg_s']:.0f} "
              f"max {v['rate_max_deg_s']:.0f} deg/s")
    a = r["at_recommended"]
    print(f"  knee {r['knee_hz']:.2f} Hz, 20 Hz line {r['line20_over_floor']:.0f}x floor -> recommended"
          f" cutoff {r['recommended_cutoff_hz']:.0f} Hz (|acc| p99 {a['acc_p99']:.2f}, max "
          f"{a['acc_max']:.2f} m/s2 at {a['acc_max_at_s']:.1f} s)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--gt-dir", type=Path, default=DEFAULT_GT)
    ap.add_argument("--out", type=Path, default=HERE)
    ap.add_argument("--window", type=float, default=0.1, help="Savitzky-Golay window (s)")
    ap.add_argument("--files", nargs="+", default=FILES)
    args = ap.parse_args()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5))
    result = {}
    for name in args.files:
        r, (f, P) = analyse(args.gt_dir / f"{name}.txt", args.window)
        result[name] = r
        report(name, r)
        ax.loglog(f[1:], P[1:], lw=0.8, label=f"{name} (knee {r['knee_hz']:.1f} Hz)")
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel("PSD of |d2p/dt2| summed over axes ((m/s^2)^2/Hz)")
    ax.set_title("EuRoC ground truth: twice-differentiated positions")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    args.out.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out / "gt_acceleration_psd.png", dpi=110, bbox_inches="tight")
    (args.out / "gt_smoothness.json").write_text(json.dumps(result, indent=2))
    print("wrote", args.out / "gt_smoothness.json", "and", args.out / "gt_acceleration_psd.png")


if __name__ == "__main__":
    main()
