"""Tests of stereo_depth_error.py on hand-made rigs: a principal-point shift of cam1 is a
disparity offset of the same size, a focal-length change of both cameras is a pure scale, and the
true calibration has neither."""
import os
import tempfile
import unittest

import numpy as np

import residual_sources_test as rs_test
import stereo_depth_error as sde

INTRINSICS = [458.6, 457.3, 367.2, 248.4]
DISTORTION = [-0.28, 0.07, 0.0002, 0.00002]


def camera_yaml(x_m, intrinsics):
    body_from_cam = np.eye(4)
    body_from_cam[0, 3] = x_m
    return rs_test.camera_yaml(body_from_cam, intrinsics, DISTORTION)


def write_rig(folder, cam0_intrinsics, cam1_intrinsics):
    paths = []
    for name, x_m, intrinsics in (('cam0', 0.0, cam0_intrinsics), ('cam1', 0.11, cam1_intrinsics)):
        path = os.path.join(folder, f'{name}.yaml')
        with open(path, 'w') as f:
            f.write(camera_yaml(x_m, intrinsics))
        paths.append(path)
    return sde.load_rig(*paths)


class StereoDepthErrorTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.truth = write_rig(os.path.join(self.tmp.name), INTRINSICS, INTRINSICS)

    def tearDown(self):
        self.tmp.cleanup()

    def rig(self, sub, cam0, cam1):
        folder = os.path.join(self.tmp.name, sub)
        os.makedirs(folder)
        return write_rig(folder, cam0, cam1)

    def fit(self, rig):
        depth, true_range, est_range, disparity, needed, f, b = sde.depth_error(self.truth, rig)
        return sde.fit_offset_scale(depth, true_range, est_range, f, b), disparity - needed

    def test_the_truth_has_no_error(self):
        (offset, scale), per_point = self.fit(self.truth)
        self.assertLess(abs(offset), 1e-6)
        self.assertLess(abs(scale), 1e-9)
        self.assertLess(np.abs(per_point).max(), 1e-6)

    def test_a_principal_point_shift_of_cam1_is_a_disparity_offset(self):
        shifted = list(INTRINSICS)
        shifted[2] += 0.3  # the file says cam1's cx is 0.3 px further right than it is
        (offset, scale), per_point = self.fit(self.rig('cx1', INTRINSICS, shifted))
        # Undistorted with a cx 0.3 px too large, cam1's columns come out 0.3 px too far left:
        # disparities 0.3 px too large at every depth. Towards the corners the undistortion
        # stretches the shift (barrel distortion, k1 = -0.28), so single points see up to 0.5 px.
        self.assertAlmostEqual(offset, 0.3, delta=0.01)
        self.assertLess(abs(scale), 1e-3)
        self.assertAlmostEqual(np.median(per_point), 0.3, delta=0.03)
        self.assertGreater(np.percentile(per_point, 5), 0.25)

    def test_a_focal_length_error_of_both_cameras_is_a_scale(self):
        longer = list(INTRINSICS)
        longer[0] *= 1.01
        longer[1] *= 1.01
        (offset, scale), _ = self.fit(self.rig('focal', longer, longer))
        # Depth scales with the focal length; the lateral coordinates of the points off the axis
        # move with the distortion evaluated at other radii, which adds about a tenth.
        self.assertLess(abs(offset), 0.01)
        self.assertAlmostEqual(scale, 0.0105, delta=1.5e-3)


if __name__ == '__main__':
    unittest.main()
