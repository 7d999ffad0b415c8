#!/usr/bin/python3
"""Tables of the PKS study (docs/pks_study.md) from a collected bench report.

Reads REPORT/results.csv (one row per run) and the analysis of bench/bench_statistics.py
(run here, on the same rows), and prints markdown:
  1. per sequence and sensor: mean ± std ATE (Sim(3)) per configuration, with the change
     against the baseline, its bootstrap 95% interval and the Mann-Whitney p;
  2. per sensor and configuration: ATE Sim(3) and SE(3), failures, suspect runs (stats.json
     "estimate"), coverage, keyframes in
     the final map, CPU time and mapping CPU time (means over runs);
  3. keyframes created per rule (mean per run), the reason counts;
  4. the pooled significance sentences;
  5. when run k of every configuration replays the same rendering (round 2, issue 39): the
     paired analysis of bench/paired_statistics.py (--compare CONFIG:BASELINE, repeatable);
  6. --rate-pairs A:B,...: keyframes created per minute of A beside B's per sequence (e.g.
     pkslam's pks-released beside the authors' binary), and whether A is within 10% of B;
  7. the builds that made the runs (per configuration). Runs of several pkslam builds, or of
     several builds of one peer, are refused (exit 3) unless --pool-builds says to pool them.

  /usr/bin/python3 evaluation/studies/pks/study_tables.py REPORT/results.csv \
      [--datasets real_MH_01_easy,real_V1_01_easy] [--compare pks-authors:orbslam3-v03-peer] \
      [--rate-pairs pks-released:pks-authors] [--pool-builds] > tables.md
"""

import argparse
import collections
import csv
import math
import os
import sys

REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..")
sys.path.insert(0, os.path.join(REPO, "bench"))
import bench_statistics  # noqa: E402  (bench/bench_statistics.py)


num = bench_statistics.number  # float or NaN


def short(dataset):
    return dataset.replace("real_", "").rsplit("_", 1)[0] if dataset.startswith("real_") \
        else dataset


def mean(values):
    values = [v for v in values if math.isfinite(v)]
    return sum(values) / len(values) if values else math.nan


def pct(v):
    return "n/a" if not math.isfinite(v) else f"{v:+.0f}%"


def per_sequence_table(result, datasets, sensors, configs, baseline):
    outcome = {(o["dataset"], o["sensor"], o["config"]): o for o in result["outcomes"]}
    change = {(s["dataset"], s["sensor"], s["config"]): s for s in result["per_sequence"]}
    lines = ["| sequence | sensor | " + " | ".join(configs) + " |",
             "|---|---|" + "---|" * len(configs)]
    for sensor in sensors:
        for dataset in datasets:
            if (dataset, sensor, baseline) not in outcome:
                continue
            cells = []
            for config in configs:
                o = outcome.get((dataset, sensor, config))
                if o is None:
                    cells.append("—")
                    continue
                text = (f"{bench_statistics.fmt(o['ate_mean'])} ± "
                        f"{bench_statistics.fmt(o['ate_std'])}")
                if o["failures"]:
                    text += f", {o['failures']}/{o['runs']} failed"
                s = change.get((dataset, sensor, config))
                if s is not None:
                    text += (f" ({pct(s['ate_change_pct'])} [{pct(s['ci_low'])}, "
                             f"{pct(s['ci_high'])}], p = {s['p']:.2g})")
                cells.append(text)
            lines.append(f"| {short(dataset)} | {sensor} | " + " | ".join(cells) + " |")
    return lines


def summary_table(rows, sensors, configs):
    lines = ["| sensor | config | runs | failed | suspect | coverage | ATE Sim(3) [m] | "
             "ATE SE(3) [m] | keyframes | CPU [s] | mapping CPU [s] |", "|---|---|" + "---|" * 9]
    for sensor in sensors:
        for config in configs:
            g = [r for r in rows if r["sensor"] == sensor and r["config"] == config]
            if not g:
                continue
            ok = [r for r in g if r["ok"]]
            known = [r for r in ok if math.isfinite(r.get("suspect", math.nan))]
            suspect = str(sum(1 for r in known if r["suspect"] == 1)) if known else "—"
            lines.append(
                f"| {sensor} | {config} | {len(g)} | {len(g) - len(ok)} | {suspect} | "
                f"{mean([r['coverage'] for r in g]):.1%} | "
                f"{mean([r['ate'] for r in ok]):.4f} | "
                f"{mean([num(r['raw']['ate_se3_rmse_m']) for r in ok]):.4f} | "
                f"{mean([num(r['raw']['keyframes']) for r in g]):.0f} | "
                f"{number(mean([num(r['raw']['cpu_s']) for r in g]), 0)} | "
                f"{number(mean([num(r['raw']['mapping_cpu_s']) for r in g]), 0)} |")
    return lines


def reason_table(rows, sensors, configs, top=6):
    lines = ["| sensor | config | keyframes created per run, by rule |", "|---|---|---|"]
    for sensor in sensors:
        for config in configs:
            g = [r for r in rows if r["sensor"] == sensor and r["config"] == config]
            if not g:
                continue
            counts = collections.Counter()
            for r in g:
                for item in (r["raw"].get("keyframe_reasons") or "").split():
                    name, _, value = item.rpartition("=")
                    counts[name] += num(value) if math.isfinite(num(value)) else 0
            total = sum(counts.values()) / len(g)
            parts = [f"{name} {value / len(g):.0f}" for name, value in counts.most_common(top)]
            rest = len(counts) - top
            lines.append(f"| {sensor} | {config} | {total:.0f}: " + ", ".join(parts) +
                         (f", … ({rest} more)" if rest > 0 else "") + " |")
    return lines


RATE_TOLERANCE = 0.10  # issue 39: pks-released's rate within 10% of the authors' binary


def created_per_minute(rows):
    """Mean over runs of keyframes created per minute of sequence (NaN without the counts)."""
    rates = [num(r["raw"].get("keyframes_created")) / (num(r["raw"].get("sequence_s")) / 60.0)
             for r in rows]
    rates = [v for v in rates if math.isfinite(v)]
    return sum(rates) / len(rates) if rates else math.nan


def number(x, digits):
    """x with `digits` decimals, or a dash when there is none (a configuration without runs)."""
    return f"{x:.{digits}f}" if math.isfinite(x) else "—"


def rate_table(rows, datasets, sensors, pairs):
    lines = ["| sequence | sensor | configuration | keyframes created / min | beside | ratio | "
             "within 10% |", "|---|---|---|---|---|---|---|"]
    for sensor in sensors:
        for dataset in datasets:
            for a, b in pairs:
                ra = created_per_minute([r for r in rows if (r["dataset"], r["sensor"],
                                                             r["config"]) == (dataset, sensor, a)])
                rb = created_per_minute([r for r in rows if (r["dataset"], r["sensor"],
                                                             r["config"]) == (dataset, sensor, b)])
                if not (math.isfinite(ra) or math.isfinite(rb)):
                    continue
                ratio = ra / rb if math.isfinite(ra) and math.isfinite(rb) and rb > 0 else math.nan
                within = ("yes" if abs(ratio - 1) <= RATE_TOLERANCE + 1e-9 else "**no**") \
                    if math.isfinite(ratio) else "—"
                lines.append(f"| {short(dataset)} | {sensor} | {a} | {number(ra, 1)} | "
                             f"{b} {number(rb, 1)} | {number(ratio, 2)} | {within} |")
    return lines


def pairs_argument(texts, parser):
    if not texts:
        return []
    try:
        return bench_statistics.paired_statistics.parse_pairs(texts)
    except ValueError as e:
        parser.error(str(e))


def builds_table(rows, configs):
    """Which build made how many of each configuration's runs."""
    lines = ["| configuration | build | runs |", "|---|---|---|"]
    for config in configs:
        counts = collections.Counter(r["build"] or "not recorded" for r in rows
                                     if r["config"] == config)
        lines += [f"| {config} | {b} | {n} |" for b, n in counts.items()]
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("results", help="REPORT/results.csv of pkslam bench --collect")
    parser.add_argument("--datasets", default="",
                        help="comma-separated datasets to keep (default: all)")
    parser.add_argument("--compare", action="append", default=[], metavar="CONFIG:BASELINE",
                        help="a paired comparison (repeatable; default: each configuration "
                             "against the suite's baseline)")
    parser.add_argument("--rate-pairs", default="", metavar="A:B,...",
                        help="keyframe rates of A beside B per sequence")
    parser.add_argument("--pool-builds", action="store_true",
                        help="analyse runs of different builds together (refused by default)")
    args = parser.parse_args()
    compare = pairs_argument(args.compare, parser)
    rate_pairs = pairs_argument([args.rate_pairs] if args.rate_pairs else [], parser)
    try:
        rows = bench_statistics.read_rows(args.results)
    except (OSError, ValueError) as e:
        sys.exit(f"study_tables: {args.results}: {e}")
    with open(args.results, newline="") as f:
        raw = {int(x["index"]): x for x in csv.DictReader(f)}
    for r in rows:
        r["raw"] = raw[r["index"]]
    if args.datasets:
        keep = set(args.datasets.split(","))
        rows = [r for r in rows if r["dataset"] in keep]
    if not rows:
        sys.exit(f"study_tables: {args.results}: no runs left")
    mixed = bench_statistics.pooled_builds(rows)
    if mixed and not args.pool_builds:
        print(f"study_tables: {args.results}: {mixed}; pass --pool-builds to analyse them "
              "together", file=sys.stderr)
        sys.exit(3)
    result = bench_statistics.analyse(rows, pairs=compare or None)
    datasets = bench_statistics.unique(r["dataset"] for r in rows)
    sensors = bench_statistics.unique(r["sensor"] for r in rows)
    configs = bench_statistics.unique(r["config"] for r in rows)
    baseline = rows[0]["baseline"]
    configs = [baseline] + [c for c in configs if c != baseline]
    out = ["**Per sequence** (mean ± std ATE Sim(3) [m]; change against "
           f"{baseline}, bootstrap 95% CI, Mann-Whitney p)", ""]
    out += per_sequence_table(result, datasets, sensors, configs, baseline)
    out += ["", "**Per selector** (means over runs)", ""]
    out += summary_table(rows, sensors, configs)
    out += ["", "**Reason counts** (keyframes created, before culling)", ""]
    out += reason_table(rows, sensors, configs)
    out += ["", "**Pooled** (stratified permutation test, Holm over the configurations)", ""]
    out += ["- " + e["sentence"] for e in result["pooled"]]
    if "paired" in result:
        out += ["", bench_statistics.paired_statistics.markdown(result["paired"])]
    if rate_pairs:
        out += ["", "**Keyframe rates** (keyframes created, culled ones too, per minute of "
                "sequence; mean over runs)", ""]
        out += rate_table(rows, datasets, sensors, rate_pairs)
    out += ["", "**Builds** (what made the runs)", ""]
    out += builds_table(rows, configs)
    print("\n".join(out))


if __name__ == "__main__":
    main()
