"""Tests of study_tables.py on a hand-made results.csv (CTest: pks_study_tables).

  /usr/bin/python3 -m unittest study_tables_test   (from evaluation/studies/pks)
"""

import csv
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
FIELDS = ["index", "dataset", "sensor", "config", "baseline", "status", "ate_m",
          "ate_se3_rmse_m", "coverage", "keyframes", "cpu_s", "mapping_cpu_s",
          "keyframe_reasons", "sweep_param", "seed", "keyframes_created", "sequence_s",
          "pkslam_commit", "executable"]


def write_results(path, rebuilt_runs=0):
    """The last `rebuilt_runs` pkslam runs come from a second build of the same commit."""
    rows, index = [], 0
    for dataset in ("real_MH_01_easy", "real_V1_01_easy"):
        for config in ("orbslam3", "pks"):
            for run in range(4):
                failed = config == "pks" and dataset == "real_V1_01_easy" and run == 0
                rows.append({
                    "index": index, "dataset": dataset, "sensor": "stereo-inertial",
                    "config": config, "baseline": "orbslam3",
                    "status": "failed" if failed else "ok",
                    "ate_m": "" if failed else 0.010 + 0.001 * run,
                    "ate_se3_rmse_m": "" if failed else 0.020, "coverage": 0.1 if failed else 1,
                    "keyframes": 100 if config == "pks" else 50, "cpu_s": 10, "mapping_cpu_s": 4,
                    "keyframe_reasons": ("imu=6 time=2" if config == "pks" else "c1b+c2=3"),
                    "sweep_param": "", "seed": run + 1,
                    "keyframes_created": 33 if config == "pks" else 30, "sequence_s": 60,
                    "pkslam_commit": "abc123", "executable": "build-a"})
                index += 1
    for r in rows[len(rows) - rebuilt_runs:]:
        r["executable"] = "build-b"
    # A sweep row: left out of every table.
    rows.append(dict(rows[0], index=index, config="orbslam3-sweep", sweep_param="min_frames"))
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=FIELDS)
        writer.writeheader()
        writer.writerows(rows)


class StudyTablesTest(unittest.TestCase):
    def run_tables(self, *extra, rebuilt_runs=0):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "results.csv")
            write_results(path, rebuilt_runs)
            return subprocess.run([sys.executable, os.path.join(HERE, "study_tables.py"), path,
                                   *extra], capture_output=True, text=True)

    def test_tables_count_failures_keyframes_and_reasons(self):
        out = self.run_tables()
        self.assertEqual(out.returncode, 0, out.stderr)
        text = out.stdout
        self.assertIn("| MH_01 | stereo-inertial | 0.0115 ± 0.0013 |", text)
        self.assertIn("1/4 failed", text)  # pks on V1_01
        self.assertIn("| stereo-inertial | pks | 8 | 1 | — | 88.8% |", text)  # no suspect column
        self.assertIn("| stereo-inertial | pks | 8: imu 6, time 2 |", text)
        self.assertIn("| stereo-inertial | orbslam3 | 3: c1b+c2 3 |", text)
        self.assertNotIn("orbslam3-sweep", text)
        self.assertIn("pks vs orbslam3 (stereo-inertial, 2 sequences", text)
        self.assertIn("fewer than 5 runs per sequence", text)  # 4 runs: no verdict

    def test_paired_analysis_and_keyframe_rates(self):
        out = self.run_tables("--compare", "pks:orbslam3", "--rate-pairs", "pks:orbslam3")
        self.assertEqual(out.returncode, 0, out.stderr)
        text = out.stdout
        self.assertIn("### Paired analysis", text)
        self.assertIn("| stereo-inertial | pks vs orbslam3 | 2 | 8 |", text)
        self.assertIn("| MH_01 | stereo-inertial | pks | 33.0 | orbslam3 30.0 | 1.10 | yes |",
                      text)
        # A partner without runs (a study stopped part-way): dashes, not "nan".
        out = self.run_tables("--rate-pairs", "pks:pks-authors")
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("| MH_01 | stereo-inertial | pks | 33.0 | pks-authors — | — | — |", out.stdout)
        self.assertNotIn("nan", out.stdout)
        bad = self.run_tables("--rate-pairs", "pks")
        self.assertNotEqual(bad.returncode, 0)

    def test_runs_of_two_builds_are_pooled_only_when_asked(self):
        out = self.run_tables()
        self.assertIn("| pks | pkslam abc123 (executable build-a) | 8 |", out.stdout)
        out = self.run_tables(rebuilt_runs=2)
        self.assertEqual(out.returncode, 3)
        self.assertIn("pkslam runs come from 2 builds", out.stderr)
        self.assertIn("build-b): 2 runs", out.stderr)
        out = self.run_tables("--pool-builds", rebuilt_runs=2)
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("| pks | pkslam abc123 (executable build-a) | 6 |", out.stdout)
        self.assertIn("| pks | pkslam abc123 (executable build-b) | 2 |", out.stdout)

    def test_dataset_filter_and_empty_selection(self):
        out = self.run_tables("--datasets", "real_MH_01_easy")
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertNotIn("V1_01", out.stdout)
        out = self.run_tables("--datasets", "real_V2_01_easy")
        self.assertNotEqual(out.returncode, 0)
        self.assertIn("no runs left", out.stderr)


if __name__ == "__main__":
    unittest.main()
