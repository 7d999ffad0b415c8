#!/usr/bin/python3
"""Which rule created how many keyframes, for every keyframe selector: runs `pkslam run` with
each selector on one dataset and sensor (deterministic) and tables stats.json's
keyframe_reasons and selector_criteria.

  /usr/bin/python3 evaluation/studies/pks/reason_counts.py --pkslam build/bin/pkslam \\
      --dataset v102_20s --sensor stereo-inertial --out reasons_si
"""

import argparse
import json
import os
import subprocess
import sys

SELECTORS = ["orbslam3", "pks", "pks-released", "interval", "ptam", "match-count",
             "vins-parallax"]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--pkslam", required=True)
    p.add_argument("--dataset", required=True)
    p.add_argument("--sensor", default="stereo-inertial")
    p.add_argument("--out", required=True)
    p.add_argument("--selectors", nargs="*", default=SELECTORS)
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    print(f"| selector | keyframes (final) | created by rule (count) | criteria held / decisions |")
    print("|---|---|---|---|")
    for selector in a.selectors:
        run = os.path.join(a.out, selector)
        with open(run + ".log", "w") as log:
            subprocess.run([a.pkslam, "--log-level", "warn", "run", "--dataset", a.dataset,
                            "--sensor", a.sensor, "--selector", selector, "--deterministic",
                            "--out", run], check=True, stdout=log, stderr=subprocess.STDOUT)
        with open(os.path.join(run, "stats.json")) as f:
            stats = json.load(f)
        reasons = ", ".join(f"{k} {v}" for k, v in sorted(
            stats["keyframe_reasons"].items(), key=lambda kv: -kv[1]))
        crit = stats.get("selector_criteria", {})
        decisions = crit.get("decisions", 0)
        held = ", ".join(f"{k} {v}" for k, v in crit.items() if k != "decisions") or "—"
        print(f"| {selector} | {stats['keyframes']} | {reasons} | {held} / {decisions} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
