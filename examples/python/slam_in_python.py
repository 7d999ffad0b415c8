#!/usr/bin/env python3
"""pkslam from Python, step by step (run it as a script or paste the cells into a notebook).

    export PYTHONPATH=$PWD/build/python          # after scripts/build
    /usr/bin/python3 examples/python/slam_in_python.py [OUT_DIR]
"""
import glob
import os
import sys

import cv2
import numpy as np

import pkslam

out = sys.argv[1] if len(sys.argv) > 1 else "/tmp/pkslam_python_example"

# %% 1. A sequence with exact ground truth: 10 s replay of the real V1_01 flight.
root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
gt_file = os.path.join(root, "..", "shared", "data", "euroc", "groundtruth", "V1_01_easy_original.txt")
seq = pkslam.simulate(os.path.join(out, "v101"), trajectory=gt_file if os.path.exists(gt_file) else None,
                      start=5, duration=10, seed=1)

# %% 2. Stereo SLAM, one frame at a time, images as NumPy arrays. Each frame: the tracked
# keypoints (undistorted pixels, map point ids) and, now and then, the map's points. Half way
# through, localisation mode: tracking only, the map stops growing.
slam = pkslam.Slam(os.path.join(seq, "settings.yaml"), pkslam.VOCABULARY, sensor="stereo",
                   selector="pks")
print("selector", slam.selector, slam.selector_parameters)
left_files = sorted(glob.glob(os.path.join(seq, "mav0/cam0/data/*.png")))
for k, left_file in enumerate(left_files):
    if k == len(left_files) // 2:
        slam.localisation_mode = True
        print(f"frame {k}: localisation mode on with {slam.num_keyframes} keyframes")
    right_file = left_file.replace("/cam0/", "/cam1/")
    t_ns = int(os.path.basename(left_file)[:-4])
    state = slam.track_stereo(cv2.imread(left_file, cv2.IMREAD_GRAYSCALE),
                              cv2.imread(right_file, cv2.IMREAD_GRAYSCALE), t_ns)
    uv, point_ids = slam.tracked_keypoints()
    if k % 50 == 0:
        xyz, map_ids, observations = slam.map_points()
        print(f"frame {k}: {state}, {len(point_ids)} tracked keypoints, {len(map_ids)} map points")
print("last state", state, "pose\n", np.round(slam.pose(), 3))
print("keyframes at the end", slam.num_keyframes)

# %% 3. The trajectory and its error against the ground truth. EuRoC's ground truth describes
# the body (IMU): compare body poses with it, or camera poses with the extrinsic.
slam.shutdown()
gt = os.path.join(seq, "mav0/state_groundtruth_estimate0/data.csv")
t_ns, body_poses = slam.body_trajectory()
result = pkslam.evaluate(gt, (t_ns, body_poses), align="se3")
camera = pkslam.evaluate(gt, slam.camera_trajectory(), align="se3",
                         body_from_camera=slam.body_from_camera)
print(f"{len(t_ns)} poses, {slam.num_keyframes} keyframes, ATE body {1e3 * result['ate_rmse_m']:.1f} mm, "
      f"camera {1e3 * camera['ate_rmse_m']:.1f} mm")

# %% 4. Keep the map for later (pkslam run --load-map, or Slam.load_map).
slam.save_map(os.path.join(out, "v101.pkmap"))
