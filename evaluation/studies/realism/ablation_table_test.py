"""Tests of ablation_table.py: medians, ranges, failed runs and the resolved/unresolved verdict."""
import unittest

from ablation_table import build_table


def rows(variant, values, sensor='stereo-inertial'):
    out = []
    for v in values:
        ok = v is not None
        out.append({'dataset': 'V1_02_' + variant, 'sensor': sensor, 'config': 'orbslam3',
                    'status': 'ok' if ok else 'failed', 'ate_se3_rmse_m': str(v) if ok else ''})
    return out


class AblationTableTest(unittest.TestCase):
    def test_separated_ranges_are_resolved(self):
        text = build_table(rows('all', [0.020, 0.022, 0.021]) + rows('calibration_off', [0.005, 0.006, 0.007]))
        self.assertIn('0.0210 [0.0200-0.0220]', text)
        self.assertIn('calibration_off -> lower (0.29x), resolved', text)

    def test_overlapping_ranges_are_not(self):
        text = build_table(rows('all', [0.020, 0.022, 0.021]) + rows('timing_off', [0.019, 0.025, 0.020]))
        self.assertIn('timing_off -> within the run-to-run spread', text)

    def test_a_failed_run_counts_as_the_worst(self):
        text = build_table(rows('all', [0.020, 0.021, 0.022]) + rows('motion_off', [0.030, None, 0.031]))
        self.assertIn('0.0310 [0.0300-fail]', text)
        self.assertIn('motion_off -> higher', text)

    def test_one_run_per_cell_gives_no_verdict(self):
        text = build_table(rows('all', [0.020]) + rows('imu_off', [0.010]))
        self.assertNotIn('resolved', text)


if __name__ == '__main__':
    unittest.main()
