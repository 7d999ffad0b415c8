"""Tests of gyro_scale_check.py's --true-baseline copy on a hand-made render: the copy's cam1
file holds the truth's stereo translation and keeps the file's stereo rotation and cam0."""
import os
import tempfile
import unittest

import numpy as np

import gyro_scale_check as gsc
import residual_sources_test as rs_test
from calibration_truth import exp_se3, load_yaml, t_bs
from residual_sources_test import write

TRUE_BODY_FROM_CAM0 = exp_se3([-0.02, 0.07, 0.0, 0.01, -0.02, 1.56])
TRUE_CAM0_FROM_CAM1 = exp_se3([0.11, 0.0, 0.0, 0.0, 0.0, 0.0])
# The files: a rotation and translation error of the stereo rig, another of the camera-IMU one.
FILE_BODY_FROM_CAM0 = exp_se3([0.003, 0.001, -0.0026, 0.0018, 0.0026, 0.003]) @ TRUE_BODY_FROM_CAM0
FILE_CAM0_FROM_CAM1 = TRUE_CAM0_FROM_CAM1 @ exp_se3([0.0002, -0.0001, 0.0001, 0.0002, -0.0001, -0.0002])


INTRINSICS = [458.6, 457.3, 367.2, 248.4]
DISTORTION = [-0.28, 0.07, 0.0002, 0.00002]


def camera_yaml(body_from_cam):
    return rs_test.camera_yaml(body_from_cam, INTRINSICS, DISTORTION)


class TrueBaselineTest(unittest.TestCase):
    def test_the_copy_holds_the_true_translation_and_the_files_rotation(self):
        with tempfile.TemporaryDirectory() as tmp:
            seq, out = os.path.join(tmp, 'seq'), os.path.join(tmp, 'out')
            write(f'{seq}/mav0/cam0/sensor.yaml', camera_yaml(FILE_BODY_FROM_CAM0))
            write(f'{seq}/mav0/cam1/sensor.yaml',
                  camera_yaml(FILE_BODY_FROM_CAM0 @ FILE_CAM0_FROM_CAM1))
            write(f'{seq}/mav0/cam1/data.csv', '#timestamp,filename\n')
            write(f'{seq}/truth/cam0_sensor.yaml', camera_yaml(TRUE_BODY_FROM_CAM0))
            write(f'{seq}/truth/cam1_sensor.yaml',
                  camera_yaml(TRUE_BODY_FROM_CAM0 @ TRUE_CAM0_FROM_CAM1))
            os.makedirs(f'{out}/mav0')
            before = open(f'{seq}/mav0/cam1/sensor.yaml').read()
            gsc.true_baseline_files(seq, out)

            body_from_cam1 = t_bs(load_yaml(f'{out}/mav0/cam1/sensor.yaml'))
            cam0_from_cam1 = np.linalg.inv(FILE_BODY_FROM_CAM0) @ body_from_cam1
            np.testing.assert_allclose(cam0_from_cam1[:3, 3], TRUE_CAM0_FROM_CAM1[:3, 3], atol=1e-12)
            np.testing.assert_allclose(cam0_from_cam1[:3, :3], FILE_CAM0_FROM_CAM1[:3, :3],
                                       atol=1e-12)
            # The file's translation differed from the truth's; the render is only read.
            self.assertGreater(np.abs(FILE_CAM0_FROM_CAM1[:3, 3] - TRUE_CAM0_FROM_CAM1[:3, 3]).max(),
                               1e-4)
            self.assertEqual(open(f'{seq}/mav0/cam1/sensor.yaml').read(), before)
            self.assertTrue(os.path.islink(f'{out}/mav0/cam1/data.csv'))


if __name__ == '__main__':
    unittest.main()
