"""Tests of peer_band.py on a results.csv with known medians and a failed run.

  /usr/bin/python3 -m unittest peer_band_test   (from this folder; CTest: realism_peer_band)
"""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import peer_band  # noqa: E402


def row(dataset, sensor, config, ate, status='ok'):
    return {'dataset': dataset, 'sensor': sensor, 'config': config, 'status': status,
            'ate_se3_rmse_m': '' if ate is None else str(ate), 'coverage': '1'}


class PeerBandTest(unittest.TestCase):
    def test_medians_band_and_ratios(self):
        rows = [row('real_MH_01_easy', 'stereo-inertial', 'orbslam3-peer', a)
                for a in (0.05, 0.06, 0.09)]
        rows += [row('real_MH_01_easy', 'stereo-inertial', 'orbslam3', a) for a in (0.03, 0.03)]
        # V1_02: published .014; a failed run is the worst, so the median of 3 is the 2nd.
        rows += [row('real_V1_02_medium', 'stereo-inertial', 'orbslam3-peer', a)
                 for a in (0.040, 0.030)]
        rows.append(row('real_V1_02_medium', 'stereo-inertial', 'orbslam3-peer', None, 'failed'))
        rows += [row('real_V1_02_medium', 'stereo-inertial', 'pks-authors', 0.01)]
        lines, in_band, checked = peer_band.band_table(rows, {'orbslam3-peer', 'orbslam3'})
        self.assertEqual((in_band, checked), (1, 2))
        mh = next(x for x in lines if x.startswith('| real_MH_01_easy'))
        self.assertIn('0.0600 [0.050-0.090] (100%, 0)', mh)  # the peer's median first
        self.assertIn('| 1.62 | yes | 0.50 |', mh)  # 0.06 / 0.037; orbslam3 / peer
        v1 = next(x for x in lines if x.startswith('| real_V1_02_medium'))
        self.assertIn('| 2.86 | no |', v1)  # 0.040 / 0.014
        self.assertNotIn('pks-authors', '\n'.join(lines))  # not among the columns asked for


if __name__ == '__main__':
    unittest.main()
