#!/usr/bin/python3
"""IMU vibration, biases and GT-IMU time offset from the real V1_01 IMU (ADIS16448, 200 Hz).

Inputs: the EuRoC imu0/data.csv (all 145.6 s of V1_01, flight included) and the TUM ground
truth (t x y z qx qy qz qw, body = IMU frame, world z up).
  (a) take-off/landing: GT height 1 cm above its first/last second;
  (b) Welch PSD per axis of accel and gyro on the ground (rotors running, until take-off - 1 s)
      and in flight (take-off + 1 s .. landing - 1 s), in 2 Hz bins, with std and peaks;
  (c) ideal IMU from the GT (angular rate from consecutive quaternions, specific force
      R^T (p'' - g), g = (0, 0, -9.81)); coherence GT vs IMU per axis and the frequency where it
      first drops below 0.5 (2 Hz bins, skipping bins at the GT's 20 Hz artefact lines);
      vibration = IMU - GT low-passed at the motion cutoff (gt_smoothness.motion_cutoff: twice
      the knee where the GT acceleration PSD reaches its floor), its RMS above the cutoff per
      axis and its PSD in 2 Hz bins up to 100 Hz -> imu_vibration_psd.csv
      (f_lo_hz,f_hi_hz,ax,ay,az,gx,gy,gz in (m/s^2)^2/Hz and (rad/s)^2/Hz, one-sided);
  (d) time offset, t_imu = t_gt + offset, maximising the correlation of gyro and GT rate;
  (e) on the ground: gyro mean, accelerometer mean and norm (vs 9.81), accel bias given the GT
      attitude; in flight: mean IMU - GT, and the rotation/scale between gyro and GT rate.

  /usr/bin/python3 evaluation/studies/realism/imu_vibration.py [--imu CSV] [--gt TXT] [--out DIR]
Writes imu_vibration.json and imu_vibration_psd.csv into --out (default: this folder).
"""
import argparse
import json
import re
from pathlib import Path

import numpy as np
from scipy import signal
from scipy.spatial.transform import Rotation

from gt_smoothness import acceleration, angular_rate, lowpass, motion_cutoff

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[2]
DATA = REPO / "../shared/data/euroc"
G = 9.81
AXES = ("ax", "ay", "az", "gx", "gy", "gz")
LINES_HZ = (20, 40, 60, 80, 100)


def per_axis(values):
    return dict(zip(AXES, np.asarray(values, float).tolist()))


def show(d, digits=4):
    return " ".join(f"{k} {v:.{digits}g}" if v is not None else f"{k} -" for k, v in d.items())


def band_means(f, P, edges):
    return np.array([P[(f >= lo) & (f < hi)].mean(0) for lo, hi in zip(edges[:-1], edges[1:])])


def time_offset(t_imu, gyro, t_gt, w_gt):
    """offset maximising corr(gyro(t_gt + offset), w_gt(t_gt)), i.e. t_imu = t_gt + offset."""
    B = w_gt - w_gt.mean(0)

    def corr(off):
        A = np.stack([np.interp(t_gt + off, t_imu, g) for g in gyro.T], 1)
        A -= A.mean(0)
        return (A * B).sum() / np.sqrt((A * A).sum() * (B * B).sum())

    coarse = np.arange(-0.2, 0.2, 0.001)
    best = coarse[np.argmax([corr(o) for o in coarse])]
    fine = np.arange(best - 0.002, best + 0.002, 0.00005)
    c = [corr(o) for o in fine]
    return float(fine[np.argmax(c)]), float(max(c))


def segment_psd(x, fs, nperseg, edges):
    f, P = signal.welch(x, fs=fs, nperseg=nperseg, axis=0)
    above5 = f > 5
    return {"duration_s": len(x) / fs, "std": per_axis(x.std(0)),
            "peak_hz_above_5hz": per_axis(f[above5][np.argmax(P[above5], 0)]),
            "psd_2hz_bins": {a: col.tolist() for a, col in zip(AXES, band_means(f, P, edges).T)}}


def coherence_cutoff(imu, ideal, fs, edges):
    f, C = signal.coherence(imu, ideal, fs=fs, nperseg=1024, axis=0)
    Cb = band_means(f, C, edges)
    at_line = np.isin(edges[:-1], LINES_HZ) | np.isin(edges[1:], LINES_HZ)
    cut = {}
    for j, a in enumerate(AXES):
        low = np.nonzero((edges[:-1] >= 2) & ~at_line & (Cb[:, j] < 0.5))[0]
        cut[a] = float(edges[low[0]]) if len(low) else None
    return cut, Cb


def white_noise_psd(sensor_yaml):
    """One-sided PSD 2*sigma_c^2 of the continuous noise densities in the Kalibr sensor.yaml."""
    text = sensor_yaml.read_text()
    density = lambda key: float(re.search(key + r":\s*([0-9.eE+-]+)", text).group(1))
    return {"accel": 2 * density("accelerometer_noise_density") ** 2,
            "gyro": 2 * density("gyroscope_noise_density") ** 2}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--imu", type=Path, default=DATA / "V1_01_easy_static/mav0/imu0/data.csv")
    ap.add_argument("--gt", type=Path, default=DATA / "groundtruth/V1_01_easy_original.txt")
    ap.add_argument("--out", type=Path, default=HERE)
    ap.add_argument("--cutoff-hz", type=float, help="vibration cutoff (default: GT motion cutoff)")
    args = ap.parse_args()

    raw = np.loadtxt(args.imu, delimiter=",", comments="#")
    t0 = raw[0, 0] * 1e-9  # times below are seconds after the first IMU sample
    ti, gyro, accel = raw[:, 0] * 1e-9 - t0, raw[:, 1:4], raw[:, 4:7]
    gt = np.loadtxt(args.gt)
    tg, p, q = gt[:, 0] - t0, gt[:, 1:4], gt[:, 4:8]
    fs, dt = 1 / np.median(np.diff(ti)), np.median(np.diff(tg))
    ideal_gt = np.c_[Rotation.from_quat(q).inv().apply(acceleration(p, dt) + [0, 0, G]),
                     angular_rate(q, dt)]
    res = {"time_origin": "first IMU sample", "imu_rate_hz": fs, "gt_rate_hz": 1 / dt,
           "imu_span_s": float(ti[-1]), "gt_start_s": float(tg[0])}

    # (a) take-off / landing from the GT height
    z_start, z_end = np.median(p[tg < tg[0] + 1, 2]), np.median(p[tg > tg[-1] - 1, 2])
    t_to = float(tg[np.argmax(p[:, 2] - z_start > 0.01)])
    t_ld = float(tg[len(tg) - 1 - np.argmax(p[::-1, 2] - z_end > 0.01)])
    res.update(takeoff_s=t_to, landing_s=t_ld)
    ground, flight = ti < t_to - 1, (ti > t_to + 1) & (ti < t_ld - 1)
    print(f"take-off {t_to:.2f} s, landing {t_ld:.2f} s after the first IMU sample "
          f"(GT starts at {tg[0]:.2f} s)")

    # (d) time offset; the IMU then stays on its own samples (interpolating it would low-pass
    # it) and the GT is moved onto them
    flight_gt = (tg > t_to + 1) & (tg < t_ld - 1)
    offset, peak = time_offset(ti, gyro, tg[flight_gt], ideal_gt[flight_gt, 3:])
    res.update(offset_ms=1e3 * offset, offset_corr=peak, offset_convention="t_imu = t_gt + offset")
    print(f"time offset: t_imu = t_gt + {1e3 * offset:.2f} ms (gyro/GT-rate correlation {peak:.4f})")
    on_imu = lambda x: np.stack([np.interp(ti[flight] - offset, tg, c) for c in x.T], 1)
    imu, ideal = np.c_[accel, gyro][flight], on_imu(ideal_gt)

    # (b) PSDs on the ground and in flight
    edges = np.arange(0, fs / 2 + 1e-9, 2.0)
    res["psd_bins_hz"] = edges.tolist()
    for name, sel, nperseg in (("ground", ground, 256), ("flight", flight, 1024)):
        res[name] = segment_psd(np.c_[accel, gyro][sel], fs, nperseg, edges)
        print(f"{name} ({res[name]['duration_s']:.1f} s): std {show(res[name]['std'])}; "
              f"PSD peak above 5 Hz (Hz): {show(res[name]['peak_hz_above_5hz'], 3)}")

    # (c) coherence, then vibration = IMU - GT motion below the cutoff
    coh_cut, Cb = coherence_cutoff(imu, ideal, fs, edges)
    res["coherence_cutoff_hz"] = coh_cut
    res["coherence_2hz_bins"] = {a: col.round(3).tolist() for a, col in zip(AXES, Cb.T)}
    print(f"coherence IMU vs GT first < 0.5 at (Hz): {show(coh_cut, 3)}")
    print("  by band: " + "; ".join(f"{lo}-{lo + 2} Hz " + " ".join(f"{c:.2f}" for c in Cb[lo // 2])
                                    for lo in (0, 2, 4, 10, 30, 50, 70, 90)))
    knee, auto_cut, _, _ = motion_cutoff(acceleration(p, dt), 1 / dt)
    cut = args.cutoff_hz or auto_cut
    f, P = signal.welch(imu - on_imu(lowpass(ideal_gt, cut, 1 / dt)), fs=fs, nperseg=1024, axis=0)
    rms = lambda lo: np.sqrt(P[f >= lo].sum(0) * (f[1] - f[0]))
    edges_v = np.r_[cut, np.arange(2 * np.floor(cut / 2) + 2, fs / 2 + 1e-9, 2.0)]
    table = band_means(f, P, edges_v)
    floors = white_noise_psd(args.imu.parent / "sensor.yaml")
    res["vibration"] = {
        "cutoff_hz": cut, "gt_motion_knee_hz": knee,
        "cutoff_rule": "2 x knee of the GT acceleration PSD (gt_smoothness.motion_cutoff) "
                       "unless --cutoff-hz",
        "rms_above_cutoff": per_axis(rms(cut)),
        "rms_above_coherence_cutoff": {a: float(rms(c)[j]) if c else None
                                       for j, (a, c) in enumerate(coh_cut.items())},
        "white_noise_psd_from_sensor_yaml": floors,
        "median_psd_over_white_noise": {"accel": float(np.median(table[:, :3]) / floors["accel"]),
                                        "gyro": float(np.median(table[:, 3:]) / floors["gyro"])}}
    v = res["vibration"]
    print(f"vibration above {cut:g} Hz (GT motion knee {knee:.2f} Hz), RMS m/s^2 | rad/s: "
          f"{show(v['rms_above_cutoff'])}")
    print(f"  RMS above the coherence cutoffs: {show(v['rms_above_coherence_cutoff'])}")
    ratio = v["median_psd_over_white_noise"]
    print(f"  median PSD over the sensor.yaml white noise: accel {ratio['accel']:.0f}x, "
          f"gyro {ratio['gyro']:.0f}x")
    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "imu_vibration_psd.csv", "w") as out:
        out.write("f_lo_hz,f_hi_hz," + ",".join(AXES) + "\n")
        for lo, hi, row in zip(edges_v[:-1], edges_v[1:], table):
            out.write(f"{lo:g},{hi:g}," + ",".join(f"{x:.4e}" for x in row) + "\n")

    # (e) frame/scale in the motion band and biases in flight ...
    lp_imu, lp_gt = lowpass(imu[:, 3:], cut, fs), lowpass(ideal[:, 3:], cut, fs)
    U, _, Vt = np.linalg.svd((lp_imu - lp_imu.mean(0)).T @ (lp_gt - lp_gt.mean(0)))
    R = U @ np.diag([1, 1, np.linalg.det(U @ Vt)]) @ Vt
    rot = np.degrees(Rotation.from_matrix(R).as_rotvec())
    slopes = [np.polyfit(lp_gt[:, k], lp_imu[:, k], 1)[0] for k in range(3)]
    res["gyro_vs_gt_rotation_vector_deg"] = rot.tolist()
    res["gyro_vs_gt_slope_xyz"] = np.array(slopes).tolist()
    res["flight_mean_imu_minus_gt"] = per_axis((imu - ideal).mean(0))
    print(f"gyro axes vs GT body axes: rotation {np.round(rot, 2).tolist()} deg, "
          f"slopes {np.round(slopes, 4).tolist()}")
    print(f"flight mean IMU - GT: {show(res['flight_mean_imu_minus_gt'])}")

    # ... and on the ground
    on_gt = ground & (ti >= tg[0])
    att = Rotation.from_quat(np.stack([np.interp(ti[on_gt] - offset, tg, c) for c in q.T], 1))
    mean_a = accel[ground].mean(0)
    norm = np.linalg.norm(accel[ground], axis=1)
    b = res["ground_bias"] = {
        "gyro_mean_rad_s": gyro[ground].mean(0).tolist(), "accel_mean": mean_a.tolist(),
        "accel_norm_mean": float(norm.mean()), "accel_norm_std": float(norm.std()),
        "accel_norm_of_mean": float(np.linalg.norm(mean_a)),
        "scale_hint_norm_over_g": float(np.linalg.norm(mean_a) / G),
        "accel_bias_given_gt_attitude": (accel[on_gt] - att.inv().apply([0, 0, G])).mean(0).tolist()}
    print(f"ground: gyro mean {np.round(b['gyro_mean_rad_s'], 5).tolist()} rad/s, accel mean "
          f"{np.round(mean_a, 3).tolist()}, |mean| {b['accel_norm_of_mean']:.4f} m/s^2 "
          f"(mean |a| {b['accel_norm_mean']:.4f} +- {b['accel_norm_std']:.3f}) -> /9.81 = "
          f"{b['scale_hint_norm_over_g']:.4f}")
    print(f"  accel - R_gt^T g: {np.round(b['accel_bias_given_gt_attitude'], 3).tolist()} m/s^2")
    (args.out / "imu_vibration.json").write_text(json.dumps(res, indent=2))
    print("wrote", args.out / "imu_vibration.json", "and", args.out / "imu_vibration_psd.csv")


if __name__ == "__main__":
    main()
