"""Tests of residual_sources.py's variants on a hand-made render and estimate: each variant puts
exactly its part at the truth and leaves the rest at the estimate."""
import os
import tempfile
import unittest

import numpy as np

import residual_sources as rs
from calibration_truth import exp_se3, log_se3

TRUE_B0 = exp_se3([-0.02, 0.07, 0.0, 0.01, -0.02, 1.56])
TRUE_C0C1 = exp_se3([0.11, 0.0, 0.0, 0.0, 0.0, 0.0])
# The files: the truth moved by a few tenths of a degree and millimetres.
FILE_B0 = exp_se3([0.003, 0.001, -0.0026, 0.0018, 0.0026, 0.003]) @ TRUE_B0
FILE_C0C1 = TRUE_C0C1 @ exp_se3([0.0001, -0.0001, 0.0, 0.0002, -0.0001, -0.0002])
# The estimate: between the two.
EST_B0 = exp_se3([0.003, 0.001, -0.0026, 0.0005, 0.0004, 0.0002]) @ TRUE_B0
EST_C0C1 = TRUE_C0C1 @ exp_se3([0.0, 0.0, 0.0, 0.0002, 0.00002, -0.00003])


def camera_yaml(body_from_cam, intrinsics, distortion, extra=''):
    rows = ',\n         '.join(', '.join(repr(float(v)) for v in body_from_cam[i]) for i in range(4))
    return (f'%YAML:1.0\nsensor_type: camera\nT_BS:\n  cols: 4\n  rows: 4\n  data: [{rows}]\n'
            f'rate_hz: 20\nresolution: [752, 480]\ncamera_model: pinhole\n'
            f'intrinsics: {intrinsics} #fu, fv, cu, cv\ndistortion_model: radial-tangential\n'
            f'distortion_coefficients: {distortion}\n{extra}')


IMU_YAML = '%YAML:1.0\nsensor_type: imu\nrate_hz: 200.0\ngyroscope_scale_error: [0.001, 0.002, 0.0]\n'
DRAW_YAML = ('camera_imu_offset_ms: 1.0\n'
             'imu_gyro_matrix: [[1.001, 0, 0], [0, 1.005, 0], [0, 0, 0.999]]\n')


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, 'w') as f:
        f.write(text)


class VariantsTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        root = self.tmp.name
        self.render, self.run = os.path.join(root, 'render'), os.path.join(root, 'run')
        true_i = ([458.6, 457.3, 367.2, 248.4], [457.6, 456.1, 380.0, 255.2])
        file_i = ([458.0, 457.5, 366.9, 248.4], [457.0, 456.4, 379.8, 255.0])
        est_i = ([458.8, 457.8, 367.1, 248.7], [457.7, 456.7, 380.1, 255.4])
        dist = '[-0.2834, 0.0740, 0.0002, 0.00002]'
        for folder, b0, c0c1, intr, extra in (
                (os.path.join(self.render, 'truth'), TRUE_B0, TRUE_C0C1, true_i, ''),
                (os.path.join(self.render, 'mav0'), FILE_B0, FILE_C0C1, file_i, ''),
                (os.path.join(self.run, 'calibration'), EST_B0, EST_C0C1, est_i,
                 'timeshift_cam_imu: 0.00103\n')):
            truth = folder.endswith('truth')
            for i, (cam, m) in enumerate((('cam0', b0), ('cam1', b0 @ c0c1))):
                path = (os.path.join(folder, f'{cam}_sensor.yaml') if truth
                        else os.path.join(folder, cam, 'sensor.yaml'))
                write(path, camera_yaml(m, intr[i], dist, extra if cam == 'cam0' else ''))
        write(os.path.join(self.run, 'calibration', 'imu0', 'sensor.yaml'), IMU_YAML)
        write(os.path.join(self.render, 'truth', 'realism_draw.yaml'), DRAW_YAML)
        self.cal = rs.Calibrations(self.render, self.run)

    def tearDown(self):
        self.tmp.cleanup()

    def tbs(self, files, cam):
        return rs.parse_tbs(files[cam])

    def intrinsics(self, files, cam):
        return rs.load_yaml_text(files[cam])['intrinsics']

    def test_est_is_the_estimate(self):
        self.assertEqual(self.cal.variant('est'), self.cal.est)

    def test_true_is_the_truth_everywhere(self):
        f = self.cal.variant('true')
        np.testing.assert_allclose(self.tbs(f, 'cam0'), TRUE_B0, atol=1e-12)
        np.testing.assert_allclose(self.tbs(f, 'cam1'), TRUE_B0 @ TRUE_C0C1, atol=1e-12)
        self.assertEqual(self.intrinsics(f, 'cam1'), [457.6, 456.1, 380.0, 255.2])
        self.assertIn('timeshift_cam_imu: 0.001\n', f['cam0'])
        gyro = rs.load_yaml_text(f['imu0'])['gyroscope_scale_error']
        np.testing.assert_allclose(gyro, [0.001, 0.005, -0.001], atol=1e-12)

    def test_imu_rot_keeps_the_estimated_stereo_extrinsic_and_lever_arm(self):
        f = self.cal.variant('imu_rot')
        b0 = self.tbs(f, 'cam0')
        np.testing.assert_allclose(b0[:3, :3], TRUE_B0[:3, :3], atol=1e-12)
        np.testing.assert_allclose(b0[:3, 3], EST_B0[:3, 3], atol=1e-12)
        np.testing.assert_allclose(np.linalg.inv(b0) @ self.tbs(f, 'cam1'), EST_C0C1, atol=1e-12)
        self.assertEqual(self.intrinsics(f, 'cam0'), [458.8, 457.8, 367.1, 248.7])

    def test_stereo_changes_only_cam1s_pose(self):
        f = self.cal.variant('stereo')
        np.testing.assert_allclose(self.tbs(f, 'cam0'), EST_B0, atol=1e-12)
        np.testing.assert_allclose(np.linalg.inv(EST_B0) @ self.tbs(f, 'cam1'), TRUE_C0C1,
                                   atol=1e-12)
        self.assertEqual(f['imu0'], self.cal.est['imu0'])

    def test_rows_aligns_the_rows_and_keeps_the_rest(self):
        f = self.cal.variant('rows')
        c0c1 = np.linalg.inv(self.tbs(f, 'cam0')) @ self.tbs(f, 'cam1')
        rot = np.eye(4)
        rot[:3, :3] = c0c1[:3, :3] @ FILE_C0C1[:3, :3].T
        true_rot = np.eye(4)
        true_rot[:3, :3] = TRUE_C0C1[:3, :3] @ FILE_C0C1[:3, :3].T
        est_rot = np.eye(4)
        est_rot[:3, :3] = EST_C0C1[:3, :3] @ FILE_C0C1[:3, :3].T
        phi, phi_true, phi_est = (log_se3(m)[3:] for m in (rot, true_rot, est_rot))
        self.assertAlmostEqual(phi[0], phi_true[0], delta=1e-7)  # about the baseline: truth
        np.testing.assert_allclose(phi[1:], phi_est[1:], atol=1e-7)  # y, z: the estimate's
        fx, fy, cx, cy = self.intrinsics(f, 'cam1')
        self.assertEqual((fx, cx), (457.7, 380.1))
        self.assertAlmostEqual(fy, 456.1 + (457.8 - 457.3))  # cam1 truth + cam0's error
        self.assertAlmostEqual(cy, 255.2 + (248.7 - 248.4))

    def test_unknown_part_is_refused(self):
        with self.assertRaises(ValueError):
            self.cal.variant('nonsense')


if __name__ == '__main__':
    unittest.main()
