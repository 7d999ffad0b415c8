"""Tests of bench_statistics.py on runs with a known effect, none, and failures.

  /usr/bin/python3 -m unittest bench/bench_statistics_test.py   (CTest: bench_statistics)
"""

import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_statistics as bs  # noqa: E402


def rows_for(ate_by_config, sensor="stereo-inertial", datasets=("A", "B", "C", "D", "E"),
             failures=None):
    """ate_by_config: config -> function(dataset index, run) -> ATE. First config = baseline."""
    rows = []
    baseline = next(iter(ate_by_config))
    index = 0
    for d, dataset in enumerate(datasets):
        for config, ate in ate_by_config.items():
            for run in range(10):
                failed = failures is not None and failures(config, d, run)
                rows.append({"dataset": dataset, "sensor": sensor, "config": config,
                             "baseline": baseline, "ok": not failed,
                             "ate": math.inf if failed else ate(d, run),
                             "coverage": 0.2 if failed else 1.0, "index": index})
                index += 1
    return rows


class BenchStatisticsTest(unittest.TestCase):
    def setUp(self):
        bs.PERMUTATIONS = 4000  # enough for the margins below, and a quick test
        bs.BOOTSTRAP = 1000

    def test_holm_by_hand(self):
        # Sorted 0.01 x 3 = 0.03; 0.03 x 2 = 0.06; 0.04 x 1 = 0.04 -> monotone 0.06.
        self.assertEqual([round(p, 12) for p in bs.holm([0.01, 0.04, 0.03])], [0.03, 0.06, 0.06])

    def test_exact_permutation_of_complete_separation(self):
        a = np.array([1.0, 2, 3, 4, 5])
        b = np.array([6.0, 7, 8, 9, 10])
        effect, p, exact = bs.stratified_permutation([(a, b)])
        self.assertTrue(exact)
        self.assertAlmostEqual(effect, 0.5)
        self.assertAlmostEqual(p, 2 / 252)  # the two fully separated arrangements of C(10, 5)

    def test_a_twenty_percent_gain_is_found_and_matches_the_paper(self):
        rng = np.random.default_rng(3)
        base = {d: 0.03 + 0.01 * d for d in range(5)}
        noise = rng.normal(0, 0.03, size=(2, 5, 10))
        rows = rows_for({"orbslam3": lambda d, r: base[d] * math.exp(noise[0, d, r]),
                         "pks": lambda d, r: 0.819 * base[d] * math.exp(noise[1, d, r])})
        result = bs.analyse(rows)
        pooled = result["pooled"][0]
        self.assertLess(pooled["p"], 0.001)
        self.assertLess(pooled["ate_change_pct"], -15)  # lower error: negative
        self.assertLess(pooled["ci_low"], -18.1)
        self.assertGreater(pooled["ci_high"], -18.1)
        self.assertIn("significantly more accurate", pooled["sentence"])
        self.assertIn("inside", pooled["sentence"])

    def test_no_effect_with_noisy_runs_is_not_decidable(self):
        rng = np.random.default_rng(4)
        noise = rng.normal(0, 0.6, size=(2, 5, 10))
        rows = rows_for({"orbslam3": lambda d, r: 0.05 * math.exp(noise[0, d, r]),
                         "pks": lambda d, r: 0.05 * math.exp(noise[1, d, r])})
        pooled = bs.analyse(rows)["pooled"][0]
        self.assertGreater(pooled["p_holm"], 0.05)
        self.assertLess(pooled["power_for_paper"], 0.8)
        self.assertGreater(pooled["runs_for_80pct_power"], 10)
        self.assertIn("not decidable", pooled["sentence"])

    def test_no_effect_with_tight_runs_refutes_the_paper(self):
        rng = np.random.default_rng(5)
        noise = rng.normal(0, 0.02, size=(2, 5, 10))
        rows = rows_for({"orbslam3": lambda d, r: 0.05 * math.exp(noise[0, d, r]),
                         "pks": lambda d, r: 0.05 * math.exp(noise[1, d, r])})
        pooled = bs.analyse(rows)["pooled"][0]
        self.assertGreater(pooled["power_for_paper"], 0.99)
        self.assertIn("not reproduced", pooled["sentence"])

    def test_sequences_disagreeing_in_sign_are_named_when_interval_and_test_part(self):
        # Three sequences 30% worse, two 10% better, tight runs: the mean relative change
        # (+14%) has an interval that excludes 0, the stratified rank test (mean effect -0.1)
        # does not reach 5%. The sentence must say both and give the per-sequence range.
        rng = np.random.default_rng(6)
        noise = rng.normal(0, 0.02, size=(2, 5, 10))
        rows = rows_for({"orbslam3": lambda d, r: 0.05 * math.exp(noise[0, d, r]),
                         "pks": lambda d, r: (1.3 if d < 3 else 0.9) * 0.05
                         * math.exp(noise[1, d, r])})
        pooled = bs.analyse(rows)["pooled"][0]
        self.assertGreater(pooled["p_holm"], 0.05)
        self.assertGreater(pooled["ci_low"], 0)
        self.assertGreater(pooled["ate_change_pct"], 0)
        self.assertAlmostEqual(pooled["sequence_change_min_pct"], -10, delta=2)
        self.assertAlmostEqual(pooled["sequence_change_max_pct"], 30, delta=2)
        self.assertIn("excludes 0 but the rank test does not", pooled["sentence"])
        self.assertIn("-10", pooled["sentence"].split("per-sequence changes")[1][:6])

    def test_one_sequence_gives_one_p_and_the_same_sign_everywhere(self):
        # A suite of one sequence: the per-sequence row and the pooled line are the same
        # comparison, so they must carry the same test, p and ATE change.
        rng = np.random.default_rng(8)
        noise = rng.normal(0, 0.1, size=(2, 1, 10))
        rows = rows_for({"orbslam3": lambda d, r: 0.05 * math.exp(noise[0, d, r]),
                         "pks": lambda d, r: 0.045 * math.exp(noise[1, d, r])}, datasets=("A",))
        result = bs.analyse(rows)
        pooled = result["pooled"][0]
        seq = result["per_sequence"][0]
        self.assertEqual(seq["p"], pooled["p"])
        self.assertEqual(seq["ate_change_pct"], pooled["ate_change_pct"])
        self.assertLess(pooled["ate_change_pct"], 0)
        self.assertIn(f"ATE change {bs.fmt_pct(pooled['ate_change_pct'])}", pooled["sentence"])
        md = bs.markdown(result)
        self.assertIn("permutation test on ranks", md)
        self.assertNotIn("Mann-Whitney", md)

    def test_identical_runs_are_named_not_tested(self):
        rows = rows_for({"orbslam3": lambda d, r: 0.05, "pks": lambda d, r: 0.04},
                        datasets=("A", "B"))
        pooled = bs.analyse(rows)["pooled"][0]
        self.assertTrue(pooled["identical"])
        self.assertAlmostEqual(pooled["ate_change_pct"], -20.0)
        self.assertIn("same ATE (deterministic runs)", pooled["sentence"])
        self.assertNotIn("significantly", pooled["sentence"])
        md = bs.markdown(bs.analyse(rows))
        self.assertIn("0.0500 (10 identical runs)", md)
        self.assertNotIn("± 0.0000", md)

    def test_a_significant_rank_test_with_a_mean_change_around_zero_says_both(self):
        # Four sequences 20% better, one 80% worse, tight runs: ranks favour the configuration,
        # the mean relative change is about 0.
        rng = np.random.default_rng(9)
        noise = rng.normal(0, 0.02, size=(2, 5, 10))
        rows = rows_for({"orbslam3": lambda d, r: 0.05 * math.exp(noise[0, d, r]),
                         "pks": lambda d, r: (1.8 if d == 0 else 0.8) * 0.05
                         * math.exp(noise[1, d, r])})
        pooled = bs.analyse(rows)["pooled"][0]
        self.assertLess(pooled["p_holm"], 0.05)
        self.assertGreater(pooled["effect"], 0)
        self.assertIn("significantly more accurate", pooled["sentence"])
        self.assertLess(pooled["ci_low"], 0)
        self.assertGreater(pooled["ci_high"], 0)
        self.assertIn("interval on the mean change includes 0", pooled["sentence"])
        self.assertIn("per-sequence changes -2", pooled["sentence"])

    def test_failures_count_against_a_configuration(self):
        # Equal ATE where both succeed, but pks fails half its runs on every sequence.
        rows = rows_for({"orbslam3": lambda d, r: 0.05 + 0.001 * r,
                         "pks": lambda d, r: 0.05 + 0.001 * r},
                        failures=lambda c, d, r: c == "pks" and r % 2 == 0)
        result = bs.analyse(rows)
        outcome = [o for o in result["outcomes"] if o["config"] == "pks"][0]
        self.assertEqual(outcome["failures"], 5)
        self.assertAlmostEqual(outcome["failure_rate"], 0.5)
        pooled = result["pooled"][0]
        self.assertLess(pooled["effect"], 0)  # worse, although the successful ATEs are equal
        self.assertLess(pooled["p"], 0.05)
        self.assertIn("significantly less accurate", pooled["sentence"])

    def test_suspect_runs_are_counted_among_successes_and_unknown_stays_unknown(self):
        rows = rows_for({"orbslam3": lambda d, r: 0.05, "pks": lambda d, r: 0.05},
                        failures=lambda c, d, r: c == "pks" and r == 0)
        outcome = [o for o in bs.analyse(rows)["outcomes"] if o["config"] == "pks"][0]
        self.assertIsNone(outcome["suspect"])  # results from before the flag
        for row in rows:
            # Runs 0-2 flagged; run 0 of pks failed, so it counts as a failure, not as suspect.
            row["suspect"] = 1.0 if row["index"] % 10 < 3 else 0.0
        result = bs.analyse(rows)
        outcome = [o for o in result["outcomes"] if o["config"] == "pks"
                   and o["dataset"] == "A"][0]
        self.assertEqual(outcome["suspect"], 2)
        self.assertIn("| suspect |", bs.markdown(result))

    def test_markdown_names_the_rules_and_every_comparison(self):
        rows = rows_for({"orbslam3": lambda d, r: 0.05 + 0.001 * r,
                         "pks": lambda d, r: 0.05 + 0.001 * r,
                         "pks-released": lambda d, r: 0.05 + 0.001 * r})
        md = bs.markdown(bs.analyse(rows))
        self.assertIn("covers less than 50%", md)
        self.assertIn("pks vs orbslam3", md)
        self.assertIn("pks-released vs orbslam3", md)
        self.assertIn("Holm", md)


class BuildProvenanceTest(unittest.TestCase):
    HEADER = ("index,dataset,sensor,config,baseline,status,ate_m,coverage,sweep_param,"
              "pkslam_commit,executable,peer_build\n")

    def write(self, lines):
        import tempfile
        d = tempfile.mkdtemp(prefix="bench_statistics_builds")
        path = os.path.join(d, "results.csv")
        with open(path, "w") as f:
            f.write(self.HEADER + "".join(lines))
        return path

    def row(self, i, config, commit="c1", executable="e1", peer=""):
        return f"{i},A,stereo-inertial,{config},orbslam3,ok,0.01,1,,{commit},{executable},{peer}\n"

    def test_one_pkslam_build_and_one_build_per_peer_pass(self):
        path = self.write([self.row(0, "orbslam3"), self.row(1, "pks"),
                           self.row(2, "peer", peer="ORB-SLAM3 v1.0 060181f"),
                           self.row(3, "peer", peer="ORB-SLAM3 v1.0 060181f"),
                           self.row(4, "authors", peer="pks: PKS a6a7dc5")])
        self.assertIsNone(bs.pooled_builds(bs.read_rows(path)))

    def test_two_pkslam_builds_are_named_with_their_run_counts(self):
        path = self.write([self.row(0, "orbslam3"), self.row(1, "pks"),
                           self.row(2, "pks", commit="c2", executable="e2")])
        mixed = bs.pooled_builds(bs.read_rows(path))
        self.assertIn("pkslam runs come from 2 builds", mixed)
        self.assertIn("pkslam c1 (executable e1): 2 runs", mixed)
        self.assertIn("pkslam c2 (executable e2): 1 runs", mixed)

    def test_a_peer_of_two_builds_and_unrecorded_runs_beside_recorded_ones(self):
        path = self.write([self.row(0, "peer", peer="v1.0 a"), self.row(1, "peer", peer="v1.0 b"),
                           self.row(2, "pks"), self.row(3, "pks", commit="", executable="")])
        mixed = bs.pooled_builds(bs.read_rows(path))
        self.assertIn("peer runs come from 2 builds", mixed)
        self.assertIn("not recorded: 1 runs", mixed)

    def test_files_without_provenance_are_one_unknown_build(self):
        import tempfile
        d = tempfile.mkdtemp(prefix="bench_statistics_old")
        path = os.path.join(d, "results.csv")
        with open(path, "w") as f:
            f.write("index,dataset,sensor,config,baseline,status,ate_m,coverage,sweep_param\n"
                    "0,A,stereo-inertial,orbslam3,orbslam3,ok,0.01,1,\n"
                    "1,A,stereo-inertial,pks,orbslam3,ok,0.01,1,\n")
        self.assertIsNone(bs.pooled_builds(bs.read_rows(path)))

    def test_main_refuses_pooled_builds_unless_told(self):
        path = self.write([self.row(i, c, commit=f"c{i % 2}") for i, c in
                           enumerate(["orbslam3", "pks"] * 3)])
        argv = sys.argv
        try:
            sys.argv = ["bench_statistics.py", path, "--md", os.devnull]
            self.assertEqual(bs.main(), 3)
            sys.argv += ["--pool-builds"]
            self.assertEqual(bs.main(), 0)
        finally:
            sys.argv = argv


if __name__ == "__main__":
    unittest.main()
