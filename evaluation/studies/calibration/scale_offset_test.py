"""Tests of scale_offset.py on a hand-made bench: a run whose estimate leaves cam1's cx 0.2 px
large has a +0.2 px offset, a run with the true rig none; runs without OUT/calibration/ and failed
runs are left out; the sign count reads the trajectories' Sim(3) scales."""
import json
import os
import tempfile
import unittest

import scale_offset
import stereo_depth_error_test as sde_test
from residual_sources_test import write

HEADER = 'index,run_id,dataset,status,ate_m,sim3_scale\n'


class ScaleOffsetTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        root = self.tmp.name
        self.bench, self.renders = os.path.join(root, 'bench'), os.path.join(root, 'renders')
        truth = os.path.join(self.renders, 'R', 'truth')
        self.cam(truth, 'cam0_sensor.yaml', 0.0, 0.0)
        self.cam(truth, 'cam1_sensor.yaml', 0.11, 0.0)

    def tearDown(self):
        self.tmp.cleanup()

    def cam(self, folder, name, x_m, dcx):
        intrinsics = list(sde_test.INTRINSICS)
        intrinsics[2] += dcx
        write(os.path.join(folder, name), sde_test.camera_yaml(x_m, intrinsics))

    def add_run(self, config, seed, status, sim3_scale, dcx1=None):
        run = os.path.join(self.bench, 'runs', 'R', 'stereo-inertial', config, f'seed{seed}')
        write(os.path.join(run, 'result.csv'), HEADER + f'0,x,R,{status},0.005,{sim3_scale}\n')
        if dcx1 is not None:
            self.cam(os.path.join(run, 'calibration', 'cam0'), 'sensor.yaml', 0.0, 0.0)
            self.cam(os.path.join(run, 'calibration', 'cam1'), 'sensor.yaml', 0.11, dcx1)

    def test_offsets_signs_and_what_is_left_out(self):
        self.add_run('online', 1, 'ok', 1.002, dcx1=0.2)   # too near, map too small: agrees
        self.add_run('online', 2, 'ok', 0.998, dcx1=0.2)   # disagrees
        self.add_run('online', 3, 'ok', 1.0001, dcx1=0.0)  # both below the floors
        self.add_run('online', 4, 'failed', 1.002, dcx1=0.2)
        self.add_run('off', 1, 'ok', 1.01)
        rows = scale_offset.run_rows(self.bench, self.renders)
        self.assertEqual([r['run'] for r in rows],
                         [f'R/stereo-inertial/online/seed{s}' for s in (1, 2, 3)])
        self.assertAlmostEqual(rows[0]['offset_px'], 0.2, delta=0.01)
        self.assertAlmostEqual(rows[0]['map_small_pct'], 0.2, delta=1e-9)
        self.assertLess(abs(rows[2]['offset_px']), 1e-6)
        self.assertEqual(scale_offset.sign_agreement(rows), (1, 2))

    def add_covariance(self, seed, names, matrix):
        run = os.path.join(self.bench, 'runs', 'R', 'stereo-inertial', 'online', f'seed{seed}')
        units = {'cam0.cx': 'px', 'cam1.cx': 'px', 'time_offset': 'ms'}
        stats = {'calibration': {
            'parameters': [{'name': n, 'unit': units[n]} for n in units],
            'covariance_matrix': {'names': names, 'matrix': matrix}}}
        write(os.path.join(run, 'stats.json'), json.dumps(stats))

    def test_the_offsets_sigma_uses_the_cross_terms(self):
        for seed in (1, 2, 3):
            self.add_run('online', seed, 'ok', 1.002, dcx1=0.2)
        # cam1's cx alone with a 0.1 px sigma; the time offset does not move stereo depth.
        self.add_covariance(1, ['cam1.cx', 'time_offset'], [[0.01, 0.0], [0.0, 4.0]])
        # Both principal points 1 px uncertain but moving together: the offset is pinned.
        self.add_covariance(2, ['cam0.cx', 'cam1.cx'], [[1.0, 0.999], [0.999, 1.0]])
        rows = scale_offset.run_rows(self.bench, self.renders)
        self.assertAlmostEqual(rows[0]['offset_sigma_px'], 0.1, delta=0.005)
        self.assertLess(rows[1]['offset_sigma_px'], 0.06)
        self.assertIsNone(rows[2]['offset_sigma_px'])

    def test_an_empty_bench_is_an_error(self):
        self.add_run('off', 1, 'ok', 1.01)
        self.assertEqual(scale_offset.main(['scale_offset.py', self.bench, self.renders]), 1)


if __name__ == '__main__':
    unittest.main()
