"""Tests of paired_statistics.py on paired runs with a known effect, none, and failures.

  /usr/bin/python3 -m unittest bench/paired_statistics_test.py   (CTest: paired_statistics)
"""

import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import paired_statistics as ps  # noqa: E402


def paired_rows(ate, sensor="stereo-inertial", datasets=("real_MH_01_easy", "real_MH_02_easy",
                                                         "real_V1_01_easy", "real_V1_02_medium",
                                                         "real_V2_01_easy"), runs=5,
                failed=None):
    """ate: config -> function(dataset index, run) -> ATE; the first config is the baseline.
    Run k of every configuration has seed k+1 (shares its rendering)."""
    rows, baseline = [], next(iter(ate))
    for d, dataset in enumerate(datasets):
        for config, f in ate.items():
            for k in range(runs):
                bad = failed is not None and failed(config, d, k)
                rows.append({"dataset": dataset, "sensor": sensor, "config": config,
                             "baseline": baseline, "seed": str(k + 1), "ok": not bad,
                             "ate": math.inf if bad else f(d, k)})
    return rows


def render(d, k):
    """A rendering's own difficulty, shared by every configuration that replays it: large."""
    return 0.01 * (1 + d) * (1.0 + 0.5 * ((7 * k + 3 * d) % 5))


class PairedStatisticsTest(unittest.TestCase):
    def setUp(self):
        ps.PERMUTATIONS = 4000

    def pooled(self, rows, pairs=None):
        result = ps.analyse(rows, pairs)
        self.assertEqual(len(result["pooled"]), 1)
        return result, result["pooled"][0]

    def test_the_papers_effect_within_renderings_is_found_despite_render_spread(self):
        noise = lambda d, k: 1.0 + 0.01 * (((5 * k + d) % 3) - 1)  # noqa: E731
        rows = paired_rows({"orbslam3": render,
                            "pks": lambda d, k: 0.819 * render(d, k) * noise(d, k)})
        _, e = self.pooled(rows)
        self.assertAlmostEqual(e["change_pct"], -18.1, delta=0.6)
        self.assertLess(e["fixed"]["p"], 0.001)
        self.assertEqual(e["fixed"]["verdict"], ["significantly better"])
        self.assertLess(e["fixed"]["ci_low_pct"], -18.1)
        self.assertGreater(e["fixed"]["ci_high_pct"], -18.1)
        self.assertEqual(e["pairs"], 25)

    def test_no_change_is_not_distinguishable_and_the_paper_lies_outside(self):
        rows = paired_rows({"orbslam3": render,
                            "pks": lambda d, k: render(d, k) * math.exp(0.01 * (d + 1) * (((k + d) % 5) - 2))})
        _, e = self.pooled(rows)
        self.assertGreater(e["fixed"]["p"], 0.5)
        self.assertEqual(e["fixed"]["verdict"],
                         ["not distinguishable", "the paper's effect lies outside the interval"])
        self.assertEqual(e["random"]["verdict"][0], "not distinguishable")

    def test_sequences_that_disagree_widen_the_random_sequence_interval(self):
        effect = [0.70, 0.90, 0.80, 0.75, 0.95]
        rows = paired_rows({"orbslam3": render, "pks": lambda d, k: effect[d] * render(d, k)
                            * (1.0 + 0.002 * ((k % 3) - 1))})
        _, e = self.pooled(rows)
        fixed = e["fixed"]["ci_high_pct"] - e["fixed"]["ci_low_pct"]
        random = e["random"]["ci_high_pct"] - e["random"]["ci_low_pct"]
        self.assertGreater(random, 10 * fixed)
        self.assertEqual(e["fixed"]["verdict"][0], "significantly better")

    def test_a_failed_run_counts_worse_than_every_success(self):
        rows = paired_rows({"orbslam3": render, "pks": render},
                           failed=lambda c, d, k: c == "pks" and k == 0)
        diffs = ps.paired_differences(rows, "stereo-inertial", "pks", "orbslam3")
        for dataset, d in diffs.items():
            self.assertEqual(d.size, 5)
            self.assertGreater(d[0], math.log(2.0) - 1e-9)  # worst success x 2 vs its pair
            self.assertTrue(np.all(d[1:] == 0))

    def test_only_seeds_both_ran_are_pairs(self):
        rows = [r for r in paired_rows({"orbslam3": render, "pks": render}, runs=3)
                if not (r["config"] == "pks" and r["seed"] == "3")]
        diffs = ps.paired_differences(rows, "stereo-inertial", "pks", "orbslam3")
        self.assertTrue(all(d.size == 2 for d in diffs.values()))

    def test_exact_sign_flip_by_hand(self):
        p, exact = ps.sign_flip_p([np.array([1.0, 1.0, 1.0])])
        self.assertTrue(exact)
        self.assertAlmostEqual(p, 2 / 8)  # all + or all - of 8 arrangements

    def test_given_comparisons_replace_the_default(self):
        rows = paired_rows({"orbslam3": render, "pks": render, "base-peer": render,
                            "authors-peer": lambda d, k: 0.9 * render(d, k)})
        result = ps.analyse(rows, [("authors-peer", "base-peer")])
        self.assertEqual([(e["config"], e["baseline"]) for e in result["pooled"]],
                         [("authors-peer", "base-peer")])
        self.assertAlmostEqual(result["pooled"][0]["change_pct"], -10.0, places=6)

    def test_paper_numbers_per_sequence(self):
        self.assertEqual(ps.paper_key("real_MH_01_easy"), "MH01")
        self.assertEqual(ps.paper_key("V1_02_all"), "V102")
        self.assertIsNone(ps.paper_key("kitti_00"))
        self.assertAlmostEqual(ps.paper_change_pct("stereo-inertial", "real_V2_03_difficult"),
                               100 * (0.023 / 0.036 - 1))
        self.assertTrue(math.isnan(ps.paper_change_pct("stereo", "real_MH_01_easy")))

    def test_one_sequence_has_no_random_sequence_reading(self):
        rows = paired_rows({"orbslam3": render, "pks": lambda d, k: 0.9 * render(d, k)},
                           datasets=("real_MH_01_easy",))
        _, e = self.pooled(rows)
        self.assertEqual(e["random"]["verdict"], ["not computed (too few sequences or pairs)"])
        self.assertIn("renders of 1 EuRoC trajectory (", ps.sentence(e))

    def test_holm_skips_missing_p_values(self):
        self.assertEqual(ps.holm([0.01, math.nan, 0.04])[0], 0.02)
        self.assertTrue(math.isnan(ps.holm([0.01, math.nan, 0.04])[1]))

    def test_power_grows_with_precision_and_is_alpha_without_an_effect(self):
        paper = math.log(0.819)
        self.assertAlmostEqual(ps.power(0.0, 0.05, 20), ps.ALPHA, places=9)
        self.assertGreater(ps.power(paper, 0.01, 20), 0.999)
        self.assertLess(ps.power(paper, 0.5, 4), 0.1)
        # Many degrees of freedom: 80% power at (1.96 + 0.84) standard errors.
        se = 0.02
        self.assertAlmostEqual(ps.detectable_pct(se, 10000),
                               100 * (math.exp(-(1.96 + 0.8416) * se) - 1), delta=0.05)
        # Few sequences need a larger effect than many pairs with the same standard error.
        self.assertLess(ps.detectable_pct(se, 4), ps.detectable_pct(se, 50))
        self.assertTrue(math.isnan(ps.power(paper, math.nan, 0)))

    def test_a_study_this_precise_would_find_the_papers_effect(self):
        noise = lambda d, k: 1.0 + 0.01 * (((5 * k + d) % 3) - 1)  # noqa: E731
        rows = paired_rows({"orbslam3": render,
                            "pks": lambda d, k: 0.97 * render(d, k) * noise(d, k)})
        _, e = self.pooled(rows)
        self.assertGreater(e["fixed"]["power_paper"], 0.99)
        self.assertGreater(e["fixed"]["detectable_pct"], -5.0)  # finds a few per cent
        md = ps.markdown(ps.analyse(rows))
        self.assertIn("| stereo-inertial | pks vs orbslam3 | -18.1% | 100%, ", md)

    def test_markdown_scopes_every_sentence(self):
        rows = paired_rows({"orbslam3": render, "pks": lambda d, k: 0.9 * render(d, k)})
        md = ps.markdown(ps.analyse(rows))
        self.assertIn("On realistic renders of 5 EuRoC trajectories", md)
        self.assertIn("real_V2_01_easy", md)
        self.assertIn("| stereo-inertial | pks vs orbslam3 | 5 | 25 |", md)


if __name__ == "__main__":
    unittest.main()
