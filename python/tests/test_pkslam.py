"""The Python module end to end: simulate a 5 s sequence, run stereo SLAM on it through
pkslam.Slam with NumPy images, evaluate the trajectory, and check inputs are refused cleanly."""
import glob
import os

import cv2
import numpy as np
import pytest

import pkslam


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    out = tmp_path_factory.mktemp("seq") / "seq"
    return pkslam.simulate(out, duration=5.0, seed=2, motion="medium", quality="fast",
                           extra=["--no-cloud"])


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
    t_ns, poses = slam.trajectory()
    assert t_ns.dtype == np.int64 and poses.shape == (len(t_ns), 4, 4)
    assert slam.num_keyframes > 2 and slam.num_map_points > 100
    # Camera trajectory against the body ground truth: compare positions only after an SE3
    # alignment; the rig's 6 cm lever arm bounds the error from above.
    gt = os.path.join(sequence, "mav0/state_groundtruth_estimate0/data.csv")
    result = pkslam.evaluate(gt, (t_ns, poses), align="se3")
    assert result["pairs"] == len(t_ns)
    assert result["ate_rmse_m"] < 0.05
    # Map files from Python.
    map_file = tmp_path / "map.pkmap"
    slam.save_map(str(map_file))
    assert map_file.stat().st_size > 1000


def test_bad_inputs_raise(sequence):
    with pytest.raises(RuntimeError, match="no_such_settings"):
        pkslam.Slam("/no_such_settings.yaml", pkslam.VOCABULARY)
    slam = pkslam.Slam(os.path.join(sequence, "settings.yaml"), pkslam.VOCABULARY, sensor="mono")
    with pytest.raises(ValueError, match="dtype"):
        slam.track_mono(np.zeros((480, 752), np.float64), 0)
    with pytest.raises(ValueError, match="C-contiguous"):
        slam.track_mono(np.zeros((752, 480), np.uint8).T, 0)
    slam.shutdown()
    with pytest.raises(RuntimeError):
        pkslam.evaluate("/no_such_gt.csv", "/no_such_est.txt")
