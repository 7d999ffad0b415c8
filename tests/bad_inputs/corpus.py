#!/usr/bin/env python3
"""Bad-input corpus: broken datasets, settings and runs made on the fly from small simulated
sequences, each run through pkslam and classified.

  corpus.py make --pkslam BIN --work DIR      simulate the base sequences into DIR
  corpus.py run  --pkslam BIN --work DIR [--case NAME ...] [--json FILE]
  corpus.py list                              case names (CTest registers one test per case)

Classes: clean (exit != 0, one "pkslam: error:" line naming the bad input, no stats.json),
warned (exit 0, the expected warning, a stats.json flag), crashed (killed by a signal, abort,
sanitizer report, or exit 2 = internal error), hung (timeout), silent (exit 0 without the
warning, or an error run that left a stats.json), unnamed (exit != 0 without naming the
input), correct (a case that must work: exit 0, or 5 for a run allowed to find no estimate, and
its outputs pass the case's check). "noestimate" cases are clean when the run exits 5 naming why
and stats.json "estimate" says so. Signal cases are clean when the trajectory left behind
evaluates against the ground truth. `run` exits 1 unless every case is clean, warned or correct.
"""
import argparse
import json
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import time

TIMEOUT_S = 120


# --------------------------------------------------------------------------------------------
# Helpers that change a copy of a base sequence. Copies hard-link the images; a helper that
# changes a file first unlinks it, so the base stays intact.

def copy_tree(src, dst):
    if os.path.exists(dst):
        shutil.rmtree(dst)
    shutil.copytree(src, dst, copy_function=os.link)


def read_lines(path):
    with open(path) as f:
        return f.read().splitlines()


def write_lines(path, lines):
    os.unlink(path)
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def data_rows(lines):
    """Indices of the non-comment lines."""
    return [i for i, l in enumerate(lines) if l and not l.startswith("#")]


def edit_csv(path, fn):
    """fn(list of data rows as field lists) -> new list of field lists."""
    lines = read_lines(path)
    header = [l for l in lines if l.startswith("#")]
    rows = [l.split(",") for l in lines if l and not l.startswith("#")]
    write_lines(path, header + [",".join(r) for r in fn(rows)])


def imu_csv(seq):
    return os.path.join(seq, "mav0/imu0/data.csv")


def cam_csv(seq, cam):
    return os.path.join(seq, f"mav0/{cam}/data.csv")


def cam_images(seq, cam):
    d = os.path.join(seq, f"mav0/{cam}/data")
    return sorted(os.path.join(d, f) for f in os.listdir(d))


def rewrite_image(path, fn):
    import cv2
    img = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    out = fn(img)
    os.unlink(path)
    cv2.imwrite(path, out)


def scale_imu(seq, gyro=1.0, accel=1.0):
    def fn(rows):
        for r in rows:
            r[1:4] = [repr(float(v) * gyro) for v in r[1:4]]
            r[4:7] = [repr(float(v) * accel) for v in r[4:7]]
        return rows
    edit_csv(imu_csv(seq), fn)


def keep_imu_fraction(seq, lo, hi):
    edit_csv(imu_csv(seq), lambda rows: rows[int(lo * len(rows)):int(hi * len(rows))])


# --------------------------------------------------------------------------------------------
# Cases. args: pkslam arguments with {seq}, {out}, {work}; expect "error" (substrings that must
# appear in the output: the bad input's name and the reason) or "warn" (substrings + a
# stats.json key that must be non-zero / true).

class Case:
    def __init__(self, name, base, mutate, args, expect, needles, stats_key=None, runner=None,
                 limit_file_kb=None, check=None):
        self.check = check  # expect "correct": check(out) -> (ok, detail) on the outputs
        self.name = name
        self.base = base
        self.mutate = mutate
        self.args = args
        self.expect = expect
        self.needles = needles
        self.stats_key = stats_key
        self.runner = runner
        self.limit_file_kb = limit_file_kb


RUN_SI = "run --dataset {seq} --sensor stereo-inertial --quiet --out {out}"
RUN_S = "run --dataset {seq} --sensor stereo --quiet --out {out}"
RUN_M = "run --dataset {seq} --sensor mono --quiet --out {out}"
RUN_RGBD = "run --dataset {seq} --sensor rgbd --quiet --out {out}"


def m_imu_huge(seq):
    edit_csv(imu_csv(seq), lambda rows: rows[:50] + [[rows[50][0], "0", "0", "0", "1e30", "0",
                                                      "9.8"]] + rows[51:])


def m_imu_nan(seq):
    def fn(rows):
        rows[70][2] = "nan"
        return rows
    edit_csv(imu_csv(seq), fn)


def m_imu_deg(seq):
    scale_imu(seq, gyro=57.29577951308232)


def m_imu_g(seq):
    scale_imu(seq, accel=1 / 9.81)


def m_imu_late(seq):
    keep_imu_fraction(seq, 0.4, 1.0)


def m_imu_early(seq):
    keep_imu_fraction(seq, 0.0, 0.6)


def m_imu_single(seq):
    edit_csv(imu_csv(seq), lambda rows: rows[:1])


def m_imu_hole(seq):
    edit_csv(imu_csv(seq), lambda rows: rows[:400] + rows[600:])


def m_imu_missing(seq):
    shutil.rmtree(os.path.join(seq, "mav0/imu0"))


def m_mono_size(seq):
    import cv2
    for p in cam_images(seq, "cam0"):
        rewrite_image(p, lambda im: cv2.resize(im, (640, 480)))


def m_stereo_size(seq):
    import cv2
    rewrite_image(cam_images(seq, "cam1")[5], lambda im: cv2.resize(im, (640, 480)))


def m_png16(seq):
    import numpy as np
    for p in cam_images(seq, "cam0"):
        rewrite_image(p, lambda im: im.astype(np.uint16))


def m_negative_stamp(seq):
    def fn(rows):
        rows[0][0] = "-5"
        return rows
    edit_csv(cam_csv(seq, "cam0"), fn)


def m_jump(seq):
    """The last 3 frames 1000 s later (both cameras; the image files keep their names)."""
    def fn(rows):
        for r in rows[-3:]:
            r[0] = str(int(r[0]) + 1000 * 10**9)
        return rows
    edit_csv(cam_csv(seq, "cam0"), fn)
    edit_csv(cam_csv(seq, "cam1"), fn)


def m_cam1_short(seq):
    edit_csv(cam_csv(seq, "cam1"), lambda rows: rows[:-12])


def m_zero_baseline(seq):
    p = os.path.join(seq, "mav0/cam1/sensor.yaml")
    os.unlink(p)
    shutil.copy(os.path.join(seq, "mav0/cam0/sensor.yaml"), p)


def m_nfeatures(seq):
    p = os.path.join(seq, "settings.yaml")
    lines = [re.sub(r"^ORBextractor\.nFeatures:.*", "ORBextractor.nFeatures: 2e9", l)
             for l in read_lines(p)]
    write_lines(p, lines)


def m_corrupt_image(seq):
    p = cam_images(seq, "cam0")[7]
    with open(p, "rb") as f:
        head = f.read(100)
    os.unlink(p)
    with open(p, "wb") as f:
        f.write(head)


def m_empty_list(seq):
    write_lines(cam_csv(seq, "cam0"), ["#timestamp [ns],filename"])


def m_zero_depth(seq):
    import numpy as np
    d = os.path.join(seq, "depth")
    for f in os.listdir(d):
        rewrite_image(os.path.join(d, f), lambda im: np.zeros_like(im))


def m_none(seq):
    pass


def m_flip_images(seq):
    """Another recording with the same frame list: every image differs."""
    import cv2
    for cam in ("cam0", "cam1"):
        for p in cam_images(seq, cam):
            rewrite_image(p, lambda im: cv2.flip(im, 1))


def bad_bench(seq, work):
    suite = os.path.join(work, "all_failed.yaml")
    with open(suite, "w") as f:
        f.write("runs: 1\nselectors: [orbslam3]\nsensors: [stereo]\n"
                "datasets: [{name: a, path: no_such_dir}]\n")
    return suite


CASES = [
    Case("imu_huge_sample", "euroc", m_imu_huge, RUN_SI, "error",
         ["imu0/data.csv:52", "beyond"]),
    Case("imu_nan", "euroc", m_imu_nan, RUN_SI, "error", ["imu0/data.csv:72", "nan"]),
    Case("imu_gyro_in_deg_s", "euroc", m_imu_deg, RUN_SI, "error", ["imu0/data.csv", "rad/s"]),
    Case("imu_accel_in_g", "euroc", m_imu_g, RUN_SI, "error", ["imu0/data.csv", "look like g"]),
    Case("imu_starts_late", "euroc", m_imu_late, RUN_SI, "error",
         ["imu0/data.csv", "have no IMU sample"]),
    Case("imu_ends_early", "euroc", m_imu_early, RUN_SI, "error",
         ["imu0/data.csv", "have no IMU sample"]),
    Case("imu_hole", "euroc", m_imu_hole, RUN_SI, "error", ["imu0/data.csv", "have no IMU sample"]),
    Case("imu_gaps_allowed", "euroc", m_imu_hole, RUN_SI + " --allow-imu-gaps", "warn",
         ["tracked without IMU"], "frames_without_imu"),
    Case("imu_single_row", "euroc", m_imu_single, RUN_SI, "error",
         ["imu0/data.csv", "single IMU sample"]),
    Case("imu_folder_missing", "euroc", m_imu_missing, RUN_SI, "error", ["imu0", "missing"]),
    Case("mono_image_size", "euroc", m_mono_size, RUN_M, "error",
         ["cam0/data/", "640x480 image, but the calibration is 752x480"]),
    Case("stereo_image_size", "euroc", m_stereo_size, RUN_S, "error",
         ["cam1/data/", "640x480 image"]),
    Case("png_16bit_8bit_values", "euroc", m_png16, RUN_M, "error", ["cam0/data/", "16-bit"]),
    Case("corrupt_image", "euroc", m_corrupt_image, RUN_S, "error", ["cam0/data/", "decode"]),
    Case("negative_first_stamp", "euroc", m_negative_stamp, RUN_M, "error",
         ["cam0/data.csv:2", "negative timestamp"]),
    Case("empty_image_list", "euroc", m_empty_list, RUN_M, "error", ["cam0/data.csv"]),
    Case("timestamp_jump", "euroc", m_jump, RUN_S + " --realtime", "warn",
         ["timestamp jump(s)", "1000.050 s"], "timestamp_jumps"),
    Case("cam1_fewer_rows", "euroc", m_cam1_short, RUN_S, "warn", ["12 of 101 frames skipped"],
         "frames_skipped"),
    Case("zero_stereo_baseline", "euroc", m_zero_baseline, RUN_S, "error",
         ["cam1/sensor.yaml", "zero stereo baseline"]),
    Case("vocabulary_is_directory", "euroc", m_none, RUN_S + " --vocabulary {work}", "error",
         ["vocabulary is not a file"]),
    Case("settings_missing", "euroc", m_none, RUN_S + " --settings {work}/no_such.yaml", "error",
         ["no_such.yaml"]),
    Case("nfeatures_overflow", "euroc", m_nfeatures, RUN_S + " --settings {seq}/settings.yaml",
         "error", ["settings.yaml", "ORBextractor.nFeatures"]),
    Case("rgbd_zero_depth_run", "tum", m_zero_depth, RUN_RGBD, "error",
         ["depth/", "no valid depth"]),
    Case("rgbd_zero_depth_planar", "tum", m_zero_depth, "planar --dataset {seq} --out {out}",
         "error", ["depth/", "no valid depth"]),
    Case("rgbd_zero_depth_odometry", "tum", m_zero_depth,
         "rgbd-odometry --dataset {seq} --out {out}", "error", ["depth/", "no valid depth"]),
    Case("dense_other_dataset", "euroc", m_flip_images,
         "dense --run {work}/base_run --dataset {seq} --out {out}/cloud.ply", "error",
         ["not the dataset run", "base_run"]),
    Case("export_colmap_other_dataset", "euroc", m_flip_images,
         "export-colmap --run {work}/base_run --dataset {seq} --out {out}", "error",
         ["not the dataset run"]),
    Case("bench_every_run_failed", "euroc", m_none, "bench {suite} --out {out} --quiet "
         "--no-plots", "error", ["1 of 1 runs failed"]),
    Case("full_disk", "euroc", m_none, RUN_S, "error", ["cannot write", "File too large"],
         limit_file_kb=16),
]


# ---- Round 2 (issue 37): inputs from outside the project's own corpus. -----------------------

def m_blank_cam0(seq):
    """Every cam0 image one flat grey: nothing to track."""
    import numpy as np
    for p in cam_images(seq, "cam0"):
        rewrite_image(p, lambda im: np.full_like(im, 128))


def m_black_stretch(seq):
    """Frames 30-49 black in both cameras (a covered lens, a dropped exposure)."""
    import numpy as np
    for cam in ("cam0", "cam1"):
        for p in cam_images(seq, cam)[30:50]:
            rewrite_image(p, lambda im: np.zeros_like(im))


def m_no_sim_yaml(seq):
    """A recording, not a render: no sim.yaml, no pkslam marker."""
    for name in ("sim.yaml", ".pkslam-output"):
        if os.path.exists(os.path.join(seq, name)):
            os.unlink(os.path.join(seq, name))


def m_users_plots(seq):
    os.makedirs(os.path.join(seq, "plots"))
    with open(os.path.join(seq, "plots", "my_figure.pdf"), "w") as f:
        f.write("mine")


def edit_yaml(path, pattern, replacement):
    lines = [re.sub(pattern, replacement, l) for l in read_lines(path)]
    write_lines(path, lines)


def m_cam0_k1_50(seq):
    edit_yaml(os.path.join(seq, "mav0/cam0/sensor.yaml"),
              r"^distortion_coefficients: \[[^,]*,", "distortion_coefficients: [50.0,")


def m_cam0_cu_negative(seq):
    edit_yaml(os.path.join(seq, "mav0/cam0/sensor.yaml"),
              r"^intrinsics: \[([^,]*), ([^,]*), [^,]*,", r"intrinsics: [\1, \2, -3000,")


def m_settings_cx_typo(seq):
    edit_yaml(os.path.join(seq, "settings.yaml"), r"^Camera1\.cx:.*", "Camera1.cx: 3672.15")


def m_duplicate_intrinsics(seq):
    p = os.path.join(seq, "mav0/cam1/sensor.yaml")
    lines = read_lines(p)
    i = next(k for k, l in enumerate(lines) if l.startswith("intrinsics:"))
    write_lines(p, lines[:i + 1] + ["intrinsics: [458.654, 457.296, 367.215, 248.375]"] +
                lines[i + 1:])


def m_depth_factor_one(seq):
    edit_yaml(os.path.join(seq, "settings.yaml"), r"^RGBD\.DepthMapFactor:.*",
              "RGBD.DepthMapFactor: 1.0")


def m_microseconds(seq):
    def fn(rows):
        for r in rows:
            r[0] = str(int(r[0]) // 1000)
        return rows
    for csv in (cam_csv(seq, "cam0"), cam_csv(seq, "cam1"), imu_csv(seq),
                os.path.join(seq, "mav0/state_groundtruth_estimate0/data.csv")):
        edit_csv(csv, fn)


def m_seconds_list(seq):
    """--timestamps rows of whole seconds ('1600000000 name.png'), read as nanoseconds."""
    names = [os.path.basename(p) for p in cam_images(seq, "cam0")]
    with open(os.path.join(seq, "ts_seconds.txt"), "w") as f:
        for i, n in enumerate(names):
            f.write(f"{1600000000 + i} {n}\n")


def gt_rows(seq):
    return [l.split(",") for l in read_lines(os.path.join(
        seq, "mav0/state_groundtruth_estimate0/data.csv")) if l and not l.startswith("#")]


def m_identical_poses(seq):
    """81 estimate poses, all the same, over the last 1.6 s (the truth moves there)."""
    with open(os.path.join(seq, "same.txt"), "w") as f:
        for r in gt_rows(seq)[-324::4]:
            f.write(f"{int(r[0]) * 1e-9:.9f} 1 2 3 0 0 0 1\n")


def m_legacy_no_size(seq):
    """An ORB-SLAM2-style settings file without the image size."""
    with open(os.path.join(seq, "orbslam2.yaml"), "w") as f:
        f.write("%YAML:1.0\nCamera.fx: 458.654\nCamera.fy: 457.296\nCamera.cx: 367.215\n"
                "Camera.cy: 248.375\nCamera.k1: -0.28340811\nCamera.k2: 0.07395907\n"
                "Camera.p1: 0.00019359\nCamera.p2: 1.76187114e-05\nCamera.fps: 20.0\n")


def m_no_version(seq):
    with open(os.path.join(seq, "no_version.yaml"), "w") as f:
        f.write("%YAML:1.0\nCamera1.fx: 458.654\nCamera1.fy: 457.296\n")


def huge_bench(work):
    suite = os.path.join(work, "huge_runs.yaml")
    with open(suite, "w") as f:
        f.write("runs: 100000000\nselectors: [orbslam3]\nsensors: [stereo]\n"
                "datasets: [{name: a, path: no_such_dir}]\n")
    return suite


def poses_at_least(n):
    def check(out):
        path = os.path.join(out, "trajectory.txt")
        if not os.path.exists(path):
            return False, "no trajectory.txt"
        poses = sum(1 for l in read_lines(path) if l and not l.startswith("#"))
        return poses >= n, f"{poses} poses in trajectory.txt (at least {n} expected)"
    return check


RUN_IMAGES = ("run --images {seq}/mav0/cam0/data --timestamps {seq}/timestamps.txt "
              "--settings {seq}/settings.yaml --quiet --out {out}")
GT = "{seq}/mav0/state_groundtruth_estimate0/data.csv"

ROUND2_CASES = [
    # Usage errors: exit 1, one line, the nearest valid word.
    Case("usage_unknown_flag", "euroc", m_none, "run --dataset {seq} --sensr stereo --out {out}",
         "error", ["--sensr", "did you mean '--sensor'"]),
    Case("usage_bad_sensor_value", "euroc", m_none, RUN_M.replace("mono", "stero"), "error",
         ["'stero' is not one of", "did you mean 'stereo'"]),
    Case("usage_unknown_command", "euroc", m_none, "rnu --dataset {seq}", "error",
         ["unknown command 'rnu'", "did you mean 'run'"]),
    Case("images_default_mono", "euroc", m_none, RUN_IMAGES, "correct", ["sensor mono"]),
    # A run that never tracks is no estimate (exit 5), not a success.
    Case("mono_never_tracks", "euroc", m_blank_cam0, RUN_IMAGES + " --max-frames 40 --strict",
         "noestimate", ["no estimate", "0 of 40 frames", "never initialised"]),
    Case("black_frames_keep_earlier_poses", "euroc", m_black_stretch, RUN_S, "correct", [],
         check=poses_at_least(75)),
    # Outputs never change inputs nor delete what pkslam did not make.
    Case("out_is_the_dataset", "euroc", m_none, RUN_S.replace("--out {out}", "--out {seq}"),
         "error", ["is the input --dataset"]),
    Case("dense_out_onto_image", "euroc", m_none,
         "dense --run {work}/base_run --dataset {seq} --out {first_image}", "error",
         ["would overwrite a file of the input --dataset"]),
    Case("simulate_onto_recording", "euroc", m_no_sim_yaml,
         "simulate --out {seq} --no-images --duration 3 --quiet", "error",
         ["not a pkslam render"]),
    Case("bench_keeps_users_plots", "euroc", m_users_plots,
         "bench {suite} --out {seq} --quiet", "error", ["plots", "not made by pkslam"]),
    Case("save_map_is_load_map", "euroc", m_none,
         RUN_S + " --load-map {out}/x.pkmap --save-map {out}/x.pkmap", "error",
         ["is the input --load-map"]),
    # Calibration that cannot be a camera.
    Case("cam0_k1_50", "euroc", m_cam0_k1_50, RUN_S, "error",
         ["cam0/sensor.yaml", "distortion"]),
    Case("cam0_cu_negative", "euroc", m_cam0_cu_negative, RUN_S, "error",
         ["cam0/sensor.yaml", "cx -3000"]),
    Case("settings_cx_typo", "euroc", m_settings_cx_typo, RUN_S + " --settings {seq}/settings.yaml",
         "error", ["settings.yaml", "Camera1.cx", "3672.15"]),
    Case("duplicate_intrinsics", "euroc", m_duplicate_intrinsics, RUN_S, "error",
         ["cam1/sensor.yaml", "appears twice"]),
    Case("rgbd_depth_factor_one", "tum", m_depth_factor_one,
         RUN_RGBD + " --settings {seq}/settings.yaml", "error",
         ["depth/", "DepthMapFactor", "the depth factor is wrong"]),
    # Time bases.
    Case("csv_in_microseconds", "euroc", m_microseconds, RUN_SI, "error",
         ["cam0/data.csv", "microseconds"]),
    Case("timestamps_whole_seconds", "euroc", m_seconds_list,
         RUN_IMAGES.replace("{seq}/timestamps.txt", "{seq}/ts_seconds.txt"), "error",
         ["ts_seconds.txt", "Camera.fps"]),
    # Evaluation that would measure nothing, or the wrong frame.
    Case("eval_identical_poses_sim3", "euroc", m_identical_poses,
         "eval --gt " + GT + " --est {seq}/same.txt --align sim3", "error",
         ["same.txt", "one place"]),
    Case("eval_camera_against_body", "euroc", m_none,
         "eval --gt " + GT + " --est {work}/base_run/trajectory.txt", "error",
         ["trajectory.txt", "--body-from-camera"]),
    # Settings in the wild.
    Case("settings_orbslam2_without_size", "euroc", m_legacy_no_size,
         RUN_M + " --settings {seq}/orbslam2.yaml", "error", ["orbslam2.yaml", "Camera.width"]),
    Case("settings_without_version", "euroc", m_no_version,
         RUN_M + " --settings {seq}/no_version.yaml", "error",
         ["no_version.yaml", "File.version", "settings convert"]),
    # Internal words replaced by the user's.
    Case("out_unwritable", "euroc", m_none, RUN_S.replace("--out {out}", "--out /proc/pkslam/out"),
         "error", ["/proc/pkslam/out"]),
    Case("load_map_is_a_folder", "euroc", m_none, RUN_S + " --load-map {seq}", "error",
         ["is a folder, not a map file"]),
    Case("suite_runs_huge", "euroc", m_none, "bench {huge_suite} --out {out} --quiet", "error",
         ["huge_runs.yaml", "must be <= 1000"]),
    Case("simulate_duration_within_rest", "euroc", m_none,
         "simulate --out {out}/sim --duration 2 --quiet", "error", ["--duration 2", "at rest"]),
    Case("eval_offset_out_of_range", "euroc", m_none,
         "eval --gt " + GT + " --est {work}/base_run/trajectory_body.txt --t-offset 1e9", "error",
         ["--t-offset"]),
]


# --------------------------------------------------------------------------------------------
# Signals: the trajectory so far must be readable by `pkslam eval`.

def wait_for_partial_lines(out, n, proc, timeout_s=60):
    path = os.path.join(out, "trajectory.txt.partial")
    end = time.time() + timeout_s
    while time.time() < end and proc.poll() is None:
        if os.path.exists(path):
            with open(path) as f:
                if sum(1 for l in f if l and not l.startswith("#")) >= n:
                    return True
        time.sleep(0.05)
    return False


def evaluates(pkslam, seq, est, out):
    gt = os.path.join(seq, "mav0/state_groundtruth_estimate0/data.csv")
    r = subprocess.run([pkslam, "eval", "--gt", gt, "--est", est, "--body-from-camera",
                        os.path.join(out, "body_from_camera.txt")],
                       capture_output=True, text=True, timeout=60)
    return r.returncode == 0, r.stdout + r.stderr


def signal_runner(signals, expect_rc, est_name):
    def run(pkslam, seq, out, work):
        cmd = [pkslam, "run", "--dataset", seq, "--sensor", "stereo", "--realtime", "--quiet",
               "--out", out]
        proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if not wait_for_partial_lines(out, 20, proc):
            proc.kill()
            return None, "the run never wrote 20 poses to trajectory.txt.partial"
        for i, sig in enumerate(signals):
            if i:
                time.sleep(0.01)
            proc.send_signal(sig)
        try:
            output, _ = proc.communicate(timeout=TIMEOUT_S)
        except subprocess.TimeoutExpired:
            proc.kill()
            return None, "hung after the signal"
        rc = proc.returncode
        est = os.path.join(out, est_name)
        ok_eval, eval_out = evaluates(pkslam, seq, est, out) if os.path.exists(est) else (
            False, f"{est_name} missing")
        detail = f"exit {rc}; {est_name}: {'evaluates' if ok_eval else eval_out.strip()}"
        # A run killed by the second signal reports -SIGINT; interrupted runs 128 + signal.
        good = rc in expect_rc and ok_eval
        return ("clean" if good else "silent"), output + "\n" + detail
    return run


def double_sigint_runner(pkslam, seq, out, work):
    # The second SIGINT, 10 ms after the first, ends the process as soon as trajectory.txt is
    # complete (apps/cmd_run.cc): it must be there and evaluate.
    return signal_runner([signal.SIGINT, signal.SIGINT], (130, -signal.SIGINT),
                         "trajectory.txt")(pkslam, seq, out, work)


SIGNAL_CASES = [
    Case("sigint_realtime", "euroc", m_none, None, "signal", [], runner=signal_runner(
        [signal.SIGINT], (130,), "trajectory.txt")),
    Case("sigterm_realtime", "euroc", m_none, None, "signal", [], runner=signal_runner(
        [signal.SIGTERM], (143,), "trajectory.txt")),
    Case("double_sigint", "euroc", m_none, None, "signal", [], runner=double_sigint_runner),
    Case("sigkill_partial", "euroc", m_none, None, "signal", [], runner=signal_runner(
        [signal.SIGKILL], (-signal.SIGKILL,), "trajectory.txt.partial")),
]

ALL = {c.name: c for c in CASES + ROUND2_CASES + SIGNAL_CASES}


# --------------------------------------------------------------------------------------------

def simulate(pkslam, out, extra):
    cmd = [pkslam, "--log-level", "warn", "simulate", "--out", out, "--quality", "fast",
           "--quiet", "--no-cloud", "--seed", "1"] + extra
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)


def make(pkslam, work):
    os.makedirs(work, exist_ok=True)
    simulate(pkslam, os.path.join(work, "base_euroc"), ["--motion", "difficult", "--duration", "5"])
    simulate(pkslam, os.path.join(work, "base_tum"), ["--rgbd", "--motion", "medium",
                                                       "--duration", "3"])
    subprocess.run([pkslam, "run", "--dataset", os.path.join(work, "base_euroc"), "--sensor",
                    "stereo", "--quiet", "--out", os.path.join(work, "base_run")], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def classify(case, rc, output, out):
    if rc is None:
        return "hung"
    if rc < 0 or rc in (134, 139) or rc == 2 or "Sanitizer" in output or \
            "terminate called" in output:
        return "crashed"
    found = all(n in output for n in case.needles)
    stats_path = os.path.join(out, "stats.json")
    if case.expect == "correct":
        if rc != 0 and not (rc == 5 and case.check is None):
            return "unnamed" if "pkslam: error:" in output else "silent"
        ok, detail = case.check(out) if case.check else (True, "")
        return "correct" if found and ok else "silent"
    if case.expect == "noestimate":
        if rc == 0:
            return "silent"
        try:
            with open(stats_path) as f:
                reason = json.load(f)["estimate"]["no_estimate"]
        except (OSError, ValueError, KeyError):
            reason = ""
        return "clean" if rc == 5 and found and reason else "unnamed"
    if case.expect == "error":
        if rc == 0:
            return "silent"
        if os.path.exists(stats_path) and case.name != "bench_every_run_failed":
            return "silent"  # a failed run must not leave a success marker
        return "clean" if found and "pkslam: error:" in output else "unnamed"
    # warn
    if rc != 0 or not found:
        return "silent"
    try:
        with open(stats_path) as f:
            stats = json.load(f)
        flagged = stats.get("degraded") is True and stats["input"].get(case.stats_key, 0) > 0
    except (OSError, ValueError, KeyError):
        flagged = False
    return "warned" if flagged else "silent"


def run_case(pkslam, work, case):
    seq = os.path.join(work, "cases", case.name, "seq")
    out = os.path.join(work, "cases", case.name, "out")
    copy_tree(os.path.join(work, "base_" + case.base), seq)
    if os.path.exists(out):
        shutil.rmtree(out)
    os.makedirs(out)
    case.mutate(seq)
    if case.runner:
        result, output = case.runner(pkslam, seq, out, work)
        return (result or "hung"), output
    first_image = cam_images(seq, "cam0")[0] if os.path.isdir(
        os.path.join(seq, "mav0/cam0/data")) else ""
    args = case.args.format(seq=seq, out=out, work=work, suite=bad_bench(seq, work),
                            huge_suite=huge_bench(work), first_image=first_image)

    def limits():
        if case.limit_file_kb:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            n = case.limit_file_kb * 1024
            resource.setrlimit(resource.RLIMIT_FSIZE, (n, n))
    try:
        r = subprocess.run([pkslam] + args.split(), capture_output=True, text=True,
                           timeout=TIMEOUT_S, preexec_fn=limits)
        rc, output = r.returncode, r.stdout + r.stderr
    except subprocess.TimeoutExpired as e:
        rc, output = None, str(e)
    return classify(case, rc, output, out), output


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("command", choices=["make", "run", "list"])
    p.add_argument("--pkslam")
    p.add_argument("--work")
    p.add_argument("--case", action="append", default=[])
    p.add_argument("--json", help="write the classification per case here")
    p.add_argument("--verbose", action="store_true", help="print every case's output")
    a = p.parse_args()
    if a.command == "list":
        print(";".join(ALL))
        return 0
    if not a.pkslam or not a.work:
        p.error("--pkslam and --work are required")
    pkslam = os.path.abspath(a.pkslam)
    work = os.path.abspath(a.work)
    if a.command == "make":
        make(pkslam, work)
        return 0
    names = a.case or list(ALL)
    unknown = [n for n in names if n not in ALL]
    if unknown:
        p.error(f"unknown case(s): {', '.join(unknown)}")
    results = {}
    for name in names:
        result, output = run_case(pkslam, work, ALL[name])
        results[name] = result
        last = [l for l in output.strip().splitlines() if l.strip()][-1:] or [""]
        print(f"{name:32s} {result:8s} {last[0][:150]}")
        if a.verbose or result not in ("clean", "warned", "correct"):
            print("    " + output.strip().replace("\n", "\n    "))
    totals = {k: sum(1 for v in results.values() if v == k)
              for k in ("clean", "warned", "correct", "crashed", "hung", "silent", "unnamed")}
    print("totals: " + ", ".join(f"{k} {v}" for k, v in totals.items()))
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"cases": results, "totals": totals}, f, indent=1)
    return 0 if all(v in ("clean", "warned", "correct") for v in results.values()) else 1


if __name__ == "__main__":
    sys.exit(main())
