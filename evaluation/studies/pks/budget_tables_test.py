"""Tests of budget_tables.py on a hand-made results.csv (CTest: pks_budget_tables).

  /usr/bin/python3 -m unittest budget_tables_test   (from evaluation/studies/pks)
"""

import csv
import math
import os
import re
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
FIELDS = ["index", "dataset", "sensor", "config", "selector", "sweep_param", "seed", "status",
          "ate_m", "coverage", "keyframes_created", "sequence_s", "pkslam_commit", "executable"]
SLOPE = 0.3           # log ATE per log rate, the same on every sequence
PKS_EFFECT = 0.75     # pks's ATE against orbslam3's at the same rate
# Per-run noise, different on each run so the fit has a residual, small enough that the
# estimates land near the truth.
NOISE = [0.01, -0.02, 0.015, -0.005, 0.02, -0.01, 0.0, 0.012, -0.018]


def write_results(path, failed_run=False, second_build=False, drop_column=None):
    rows, index = [], 0
    for d, (dataset, level) in enumerate((("real_MH_04_difficult", 0.04),
                                          ("real_V1_02_medium", 0.01))):
        for seed in (1, 2, 3):
            block = 1.0 + 0.1 * seed  # the rendering's own difficulty, shared by its runs
            for selector, rates, effect in (("orbslam3", (100, 150, 200), 1.0),
                                            ("pks", (120, 180, 300), PKS_EFFECT)):
                for k, rate in enumerate(rates):
                    sweep = k != 1
                    config = selector if not sweep else f"{selector}@p={k}"
                    noise = NOISE[(index + d) % len(NOISE)]
                    ate = level * block * effect * (rate / 150.0) ** SLOPE * math.exp(noise)
                    failed = failed_run and index == 0
                    rows.append({
                        "index": index, "dataset": dataset, "sensor": "stereo-inertial",
                        "config": config, "selector": selector,
                        "sweep_param": "p" if sweep else "", "seed": seed,
                        "status": "ok", "ate_m": ate, "coverage": 0.3 if failed else 1.0,
                        "keyframes_created": rate * 2, "sequence_s": 120,
                        "pkslam_commit": "abc123",
                        "executable": "build-b" if second_build and index == 5 else "build-a"})
                    index += 1
    fields = [f for f in FIELDS if f != drop_column]
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)


class BudgetTablesTest(unittest.TestCase):
    def run_tables(self, *extra, **kwargs):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "results.csv")
            write_results(path, **kwargs)
            out = subprocess.run([sys.executable, os.path.join(HERE, "budget_tables.py"), path,
                                  *extra], capture_output=True, text=True)
            return out, path

    def test_recovers_the_rate_slope_and_the_selector_effect(self):
        out, _ = self.run_tables()
        self.assertEqual(out.returncode, 0, out.stderr)
        text = out.stdout
        # Rates: keyframes created per minute of sequence (rate * 2 over 2 minutes).
        self.assertIn("| MH_04 | orbslam3 | 150.0 |", text)
        self.assertIn("| V1_02 | pks@p=2 | 300.0 |", text)
        self.assertIn("36 runs in the fit (0 failed runs left out)", text)
        for sequence in ("MH_04", "V1_02"):
            slope = re.search(rf"\| {sequence} \| ([+-][0-9.]+) \[", text)
            self.assertIsNotNone(slope, text)
            self.assertAlmostEqual(float(slope.group(1)), SLOPE, delta=0.06)
        pks = re.search(r"\| pks \| ([+-][0-9.]+)% \[([+-][0-9.]+)%, ([+-][0-9.]+)%\], "
                        r"([0-9.e-]+) \| (significantly better)", text)
        self.assertIsNotNone(pks, text)
        self.assertAlmostEqual(float(pks.group(1)), 100 * (PKS_EFFECT - 1), delta=3.0)
        self.assertLess(float(pks.group(2)), 100 * (PKS_EFFECT - 1))
        self.assertGreater(float(pks.group(3)), 100 * (PKS_EFFECT - 1))
        self.assertIn("(2 sequences)", text)

    def test_a_failed_run_is_counted_and_left_out(self):
        out, _ = self.run_tables(failed_run=True)
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("35 runs in the fit (1 failed runs left out)", out.stdout)
        self.assertIn("failed (coverage 30%)", out.stdout)
        self.assertIn("| MH_04 | orbslam3@p=0 | 100.0 |", out.stdout)
        self.assertIn("| 3 (1) |", out.stdout)

    def test_runs_of_two_builds_are_pooled_only_when_asked(self):
        out, _ = self.run_tables(second_build=True)
        self.assertEqual(out.returncode, 3)
        self.assertIn("pass --pool-builds", out.stderr)
        out, _ = self.run_tables("--pool-builds", second_build=True)
        self.assertEqual(out.returncode, 0, out.stderr)

    def test_bad_input_names_the_file(self):
        out, path = self.run_tables(drop_column="keyframes_created")
        self.assertNotEqual(out.returncode, 0)
        self.assertIn("results.csv: no column keyframes_created", out.stderr)
        missing = subprocess.run([sys.executable, os.path.join(HERE, "budget_tables.py"),
                                  "/nonexistent/results.csv"], capture_output=True, text=True)
        self.assertNotEqual(missing.returncode, 0)
        self.assertIn("/nonexistent/results.csv", missing.stderr)


if __name__ == "__main__":
    unittest.main()
