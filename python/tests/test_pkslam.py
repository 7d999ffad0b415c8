"""The Python module end to end: simulate a 5 s sequence, run stereo SLAM on it through
pkslam.Slam with NumPy images, evaluate the trajectory, and check inputs are refused cleanly."""
import glob
import json
import os
import subprocess

import cv2
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import pkslam


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    out = tmp_path_factory.mktemp("seq") / "seq"
    # Difficult motion: a path that is not a straight line, so orientations tell frames apart.
    return pkslam.simulate(out, duration=5.0, seed=2, motion="difficult", quality="fast",
                           cloud=False)


def frames(seq):
    for left in sorted(glob.glob(os.path.join(seq, "mav0/cam0/data/*.png"))):
        right = left.replace("/cam0/", "/cam1/")
        if os.path.exists(right):
            t_ns = int(os.path.basename(left)[:-4])
            yield t_ns, cv2.imread(left, cv2.IMREAD_GRAYSCALE), cv2.imread(right, cv2.IMREAD_GRAYSCALE)


def test_stereo_slam_through_python_meets_the_ate_bar(sequence, tmp_path):
    slam = pkslam.Slam(os.path.join(sequence, "settings.yaml"), pkslam.VOCABULARY,
                       sensor="stereo", deterministic=True)
    states = [slam.track_stereo(left, right, t_ns) for t_ns, left, right in frames(sequence)]
    assert states.count("OK") >= 0.9 * len(states)
    pose = slam.pose()
    assert pose.shape == (4, 4) and np.allclose(pose[3], [0, 0, 0, 1])
    slam.shutdown()
    t_ns, poses = slam.camera_trajectory()
    assert t_ns.dtype == np.int64 and poses.shape == (len(t_ns), 4, 4)
    assert np.all(np.diff(t_ns) > 0)
    assert slam.num_keyframes > 2 and slam.num_map_points > 100
    gt = os.path.join(sequence, "mav0/state_groundtruth_estimate0/data.csv")
    body_t, body_poses = slam.body_trajectory()
    body = pkslam.evaluate(gt, (body_t, body_poses), align="se3")
    assert body["pairs"] == len(t_ns)
    assert body["ate_rmse_m"] < 0.05 and body["ate_rot_rmse_deg"] < 2
    # Camera poses need the extrinsic; without it they are refused with the hint, not measured.
    camera = pkslam.evaluate(gt, (t_ns, poses), align="se3",
                             body_from_camera=slam.body_from_camera)
    assert camera["ate_rot_rmse_deg"] < 2
    with pytest.raises(RuntimeError, match="body_from_camera"):
        pkslam.evaluate(gt, (t_ns, poses), align="se3")
    with pytest.raises(ValueError, match="ambiguous"):
        slam.trajectory()
    # The CLI on the same body trajectory: the same numbers.
    est = tmp_path / "body.txt"
    with open(est, "w") as f:
        for t, m in zip(body_t, body_poses):
            q = Rotation.from_matrix(m[:3, :3]).as_quat()  # x y z w
            f.write(f"{t * 1e-9:.9f} {m[0, 3]:.12f} {m[1, 3]:.12f} {m[2, 3]:.12f} "
                    f"{q[0]:.12f} {q[1]:.12f} {q[2]:.12f} {q[3]:.12f}\n")
    cli = subprocess.run([pkslam._executable(), "eval", "--gt", gt, "--est", str(est), "--json",
                          str(tmp_path / "eval.json")], capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    with open(tmp_path / "eval.json") as f:
        cli_result = json.load(f)
    assert abs(cli_result["ate"]["rmse"] - body["ate_rmse_m"]) < 1e-6
    assert abs(cli_result["rpe"]["trans_m"]["rmse"] - body["rpe_trans_rmse_m"]) < 1e-6
    # Map files from Python.
    map_file = tmp_path / "map.pkmap"
    slam.save_map(str(map_file))
    assert map_file.stat().st_size > 1000


def test_map_keypoints_localisation_mode_and_reset(sequence):
    """The script the API is for: run SLAM, read the map points and tracked keypoints each
    frame, switch to localisation mode half way (the map stops growing), evaluate the body
    trajectory; then reset and run again from an empty map."""
    slam = pkslam.Slam(os.path.join(sequence, "settings.yaml"), pkslam.VOCABULARY,
                       sensor="stereo", selector="pks", deterministic=True,
                       selector_parameters={"delta": 30})
    assert slam.selector == "pks" and slam.selector_parameters["delta"] == 30
    all_frames = list(frames(sequence))
    half = len(all_frames) // 2
    keyframes_at_switch = None
    ids_seen = set()
    for k, (t_ns, left, right) in enumerate(all_frames):
        if k == half:
            slam.localisation_mode = True
            assert slam.localisation_mode
            keyframes_at_switch = slam.keyframes()[0].size
        state = slam.track_stereo(left, right, t_ns)
        uv, point_ids = slam.tracked_keypoints()
        if state == "OK":
            assert uv.shape == (len(point_ids), 2) and len(point_ids) > 30
            assert np.all((uv[:, 0] >= 0) & (uv[:, 0] < left.shape[1]))
            ids_seen.update(point_ids.tolist())
        else:
            assert len(point_ids) == 0
        if k % 10 == 0:
            xyz, map_ids, observations = slam.map_points()
            assert xyz.shape == (len(map_ids), 3) and np.all(np.isfinite(xyz))
            assert len(map_ids) == 0 or observations.min() >= 1
    # In localisation mode no keyframe was added; tracking went on against the map.
    kf_t, kf_poses, kf_ids = slam.keyframes()
    assert len(kf_t) == keyframes_at_switch > 2
    assert kf_poses.shape == (len(kf_t), 4, 4) and np.all(np.diff(kf_t) > 0)
    _, map_ids, _ = slam.map_points()
    assert ids_seen & set(map_ids.tolist())  # tracked keypoints name points of the map
    slam.shutdown()
    gt = os.path.join(sequence, "mav0/state_groundtruth_estimate0/data.csv")
    body = pkslam.evaluate(gt, slam.body_trajectory(), align="se3")
    assert body["pairs"] >= 0.9 * len(all_frames)
    assert body["ate_rmse_m"] < 0.05
    # Reset: an empty system with the same options; frame times may start over.
    slam.reset()
    assert slam.num_keyframes == 0 and len(slam.map_points()[1]) == 0
    assert not slam.localisation_mode
    for t_ns, left, right in all_frames[:20]:
        slam.track_stereo(left, right, t_ns)
    assert slam.num_keyframes >= 1
    slam.shutdown()
    with pytest.raises(RuntimeError, match="has no parameter 'no_such_parameter'"):
        pkslam.Slam(os.path.join(sequence, "settings.yaml"), pkslam.VOCABULARY,
                    selector="pks", selector_parameters={"no_such_parameter": 1})


def test_bad_inputs_raise(sequence):
    with pytest.raises(RuntimeError, match="no_such_settings"):
        pkslam.Slam("/no_such_settings.yaml", pkslam.VOCABULARY)
    slam = pkslam.Slam(os.path.join(sequence, "settings.yaml"), pkslam.VOCABULARY, sensor="mono")
    with pytest.raises(ValueError, match="dtype"):
        slam.track_mono(np.zeros((480, 752), np.float64), 0)
    with pytest.raises(ValueError, match="C-contiguous"):
        slam.track_mono(np.zeros((752, 480), np.uint8).T, 0)
    with pytest.raises(ValueError, match="image: 640x480 image, but the settings' camera is 752x480"):
        slam.track_mono(np.zeros((480, 640), np.uint8), 0)
    with pytest.raises(ValueError, match="image: expected 8-bit"):
        slam.track_mono(np.zeros((480, 752), np.uint16), 0)
    with pytest.raises(ValueError, match="image: empty"):
        slam.track_mono(np.zeros((0, 0), np.uint8), 0)
    # BGR images are converted.
    assert slam.track_mono(np.full((480, 752, 3), 128, np.uint8), 10**9) == "NOT_INITIALIZED"
    with pytest.raises(ValueError, match="not after the previous frame"):
        slam.track_mono(np.zeros((480, 752), np.uint8), 10**9 - 1)
    slam.shutdown()
    with pytest.raises(ValueError, match="after Shutdown"):
        slam.track_mono(np.zeros((480, 752), np.uint8), 2 * 10**9)
    with pytest.raises(RuntimeError):
        pkslam.evaluate("/no_such_gt.csv", "/no_such_est.txt")
    with pytest.raises(ValueError, match="est:"):
        pkslam.evaluate("/no_such_gt.csv", [1, 2, 3])


def test_bad_imu_and_poses_raise(sequence):
    slam = pkslam.Slam(os.path.join(sequence, "settings.yaml"), pkslam.VOCABULARY,
                       sensor="stereo-inertial")
    t = np.array([1, 2, 3], np.int64)
    gyro = np.zeros((3, 3))
    gyro[1, 2] = np.nan
    with pytest.raises(ValueError, match="IMU sample 1 .*not finite"):
        slam.add_imu(t, gyro, np.zeros((3, 3)))
    slam.shutdown()
    gt = os.path.join(sequence, "mav0/state_groundtruth_estimate0/data.csv")
    with open(gt) as f:
        stamps = [int(line.split(",")[0]) for line in f if line[0].isdigit()][:50]
    poses = np.tile(np.eye(4), (50, 1, 1))
    with pytest.raises(RuntimeError, match="one place"):
        pkslam.evaluate(gt, (np.array(stamps, np.int64), poses), align="sim3")
    poses[3, 0, 3] = np.nan
    with pytest.raises(ValueError, match="estimate pose 3: not finite"):
        pkslam.evaluate(gt, (np.array(stamps, np.int64), poses))


def test_simulate_in_process_renders_the_bytes_of_the_command_line(tmp_path):
    # The library and `pkslam simulate` resolve the same request the same way (one policy in
    # sim/simulation_request.h): a short replay-free render, byte for byte.
    python_out = tmp_path / "python"
    cli_out = tmp_path / "cli"
    pkslam.simulate(python_out, duration=2.5, seed=5, motion="easy", quality="fast", cloud=False,
                    realism="euroc", realism_off=["appearance"])
    cli = subprocess.run([pkslam._executable(), "--log-level", "warn", "simulate", "--out",
                          str(cli_out), "--duration", "2.5", "--seed", "5", "--motion", "easy",
                          "--quality", "fast", "--no-cloud", "--realism", "euroc",
                          "--realism-off", "appearance", "--quiet"],
                         capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    files = sorted(os.path.relpath(f, cli_out)
                   for f in glob.glob(str(cli_out / "**" / "*"), recursive=True)
                   if os.path.isfile(f))
    assert "mav0/imu0/data.csv" in files and len(files) > 100
    for name in files:
        with open(cli_out / name, "rb") as a, open(python_out / name, "rb") as b:
            assert a.read() == b.read(), name


def test_simulate_refuses_bad_values_naming_them(tmp_path):
    with pytest.raises(ValueError, match="wild"):
        pkslam.simulate(tmp_path / "a", duration=3, motion="wild")
    with pytest.raises(ValueError, match="trajectory"):
        pkslam.simulate(tmp_path / "b", trajectory=tmp_path / "missing.txt")
    with pytest.raises(ValueError, match="sunshine"):
        pkslam.simulate(tmp_path / "c", duration=3, realism="euroc", realism_off=["sunshine"])
