#!/usr/bin/python3
"""Equal keyframe budget (issue 39 item 7, docs/pks_study.md): more keyframes, or better ones?

Reads the collected results.csv of bench/suites/pks-budget.yaml: each selector at its default
and at two more values of its rate-setting parameter (rows with `sweep_param`), plus a plain
`interval` selector, run k of every configuration on the same rendering. Prints markdown:
  1. per sequence and sensor: each configuration's keyframes created per minute (mean over
     runs), its median ATE and every run's ATE;
  2. a regression of log ATE per run on log keyframe rate and the selector, with one intercept
     per rendering (sequence and run: the pairing) and one rate slope per sequence:
       log ATE = block(sequence, run) + slope(sequence) log rate + effect(selector)
     The slope says what more keyframes buy within a selector (doubling the rate multiplies ATE
     by 2^slope); a selector's effect is its ATE against the baseline selector's at the same
     keyframe rate ("better keyframes"). Sequences fixed: one least-squares fit, t-intervals
     from its residual spread. Flights as a sample: the fit per sequence, the effects' mean
     over sequences and its t-interval (S - 1 degrees of freedom). Holm over the selectors of
     one sensor, per analysis, as bench/paired_statistics.py does.
Failed runs (bench/bench_statistics.py's rule: status not ok, no ATE, or coverage under 50%)
have no ATE to regress; they are counted per configuration and left out of the fit, which is
said beside the result. Runs of several builds are refused (exit 3) unless --pool-builds.

  /usr/bin/python3 evaluation/studies/pks/budget_tables.py \
      evaluation/studies/pks/round2/budget_results.csv [--baseline orbslam3] [--pool-builds]
"""

import argparse
import csv
import math
import os
import statistics
import sys
from collections import OrderedDict

import numpy as np
from scipy import stats

REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..")
sys.path.insert(0, os.path.join(REPO, "bench"))
import bench_statistics  # noqa: E402  (bench/bench_statistics.py)
import paired_statistics  # noqa: E402  (bench/paired_statistics.py)

num = bench_statistics.number
ALPHA = paired_statistics.ALPHA


def short(dataset):
    return dataset.replace("real_", "").rsplit("_", 1)[0] if dataset.startswith("real_") \
        else dataset


def read_runs(path):
    """One dict per run: dataset, sensor, config, selector, seed, ok, ate, rate, build."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    need = {"dataset", "sensor", "config", "selector", "seed", "status", "ate_m",
            "keyframes_created", "sequence_s"}
    missing = need - set(rows[0].keys() if rows else need)
    if not rows:
        raise ValueError("no runs")
    if missing:
        raise ValueError("no column " + ", ".join(sorted(missing)))
    runs = []
    for r in rows:
        ate, coverage = num(r["ate_m"]), num(r.get("coverage"))
        ok = r["status"] == "ok" and math.isfinite(ate) and ate > 0 and not (
            math.isfinite(coverage) and coverage < bench_statistics.MIN_COVERAGE)
        minutes = num(r["sequence_s"]) / 60.0
        rate = num(r["keyframes_created"]) / minutes if minutes > 0 else math.nan
        runs.append({"dataset": r["dataset"], "sensor": r["sensor"], "config": r["config"],
                     "selector": r["selector"], "seed": r["seed"], "ok": ok,
                     "ate": ate if ok else math.nan, "rate": rate,
                     "build": bench_statistics.build_of(r), "coverage": coverage})
    return runs


def unique(values):
    return list(OrderedDict.fromkeys(values))


def finite_mean(values):
    values = [v for v in values if math.isfinite(v)]
    return sum(values) / len(values) if values else math.nan


def per_sequence_table(runs, sensor):
    lines = ["| sequence | configuration | keyframes created / min | median ATE [mm] | "
             "runs (failed) | ATE per run [mm] |", "|---|---|---|---|---|---|"]
    for dataset in unique(r["dataset"] for r in runs if r["sensor"] == sensor):
        here = [r for r in runs if (r["dataset"], r["sensor"]) == (dataset, sensor)]
        for config in unique(r["config"] for r in here):
            g = sorted((r for r in here if r["config"] == config), key=lambda r: r["seed"])
            ok = [r["ate"] * 1e3 for r in g if r["ok"]]
            each = ", ".join(f"{r['ate'] * 1e3:.1f}" if r["ok"] else
                             f"failed (coverage {r['coverage']:.0%})" for r in g)
            median = f"{statistics.median(ok):.1f}" if ok else "—"
            lines.append(f"| {short(dataset)} | {config} | {finite_mean([r['rate'] for r in g]):.1f}"
                         f" | {median} | {len(g)} ({len(g) - len(ok)}) | {each} |")
    return lines


def design(runs, selectors):
    """(X, y, names): blocks per (dataset, seed), a log-rate slope per dataset, an effect per
    selector in `selectors` (the baseline selector is the reference level)."""
    blocks = unique((r["dataset"], r["seed"]) for r in runs)
    datasets = unique(r["dataset"] for r in runs)
    names = [f"block {d} {s}" for d, s in blocks] + [f"slope {d}" for d in datasets] + \
        [f"effect {s}" for s in selectors]
    X = np.zeros((len(runs), len(names)))
    for i, r in enumerate(runs):
        X[i, blocks.index((r["dataset"], r["seed"]))] = 1.0
        X[i, len(blocks) + datasets.index(r["dataset"])] = math.log(r["rate"])
        if r["selector"] in selectors:
            X[i, len(blocks) + len(datasets) + selectors.index(r["selector"])] = 1.0
    y = np.array([math.log(r["ate"]) for r in runs])
    return X, y, names


def least_squares(X, y):
    """(coefficients, their covariance, residual degrees of freedom); None when X is rank
    deficient (a selector or slope the runs cannot separate) or nothing is left for the
    residual."""
    rank = np.linalg.matrix_rank(X)
    dof = X.shape[0] - X.shape[1]
    if rank < X.shape[1] or dof <= 0:
        return None
    beta, *_ = np.linalg.lstsq(X, y, rcond=None)
    residual = y - X @ beta
    sigma2 = float(residual @ residual) / dof
    return beta, sigma2 * np.linalg.inv(X.T @ X), dof


def interval(estimate, se, dof):
    half = stats.t.ppf(1 - ALPHA / 2, dof) * se
    p = 2 * float(stats.t.sf(abs(estimate / se), dof)) if se > 0 else (
        1.0 if estimate == 0 else 0.0)
    return estimate - half, estimate + half, p


def fit_fixed(runs, selectors):
    """Sequences fixed: one fit. {name: (estimate, low, high, p)} and its residual dof."""
    X, y, names = design(runs, selectors)
    fitted = least_squares(X, y)
    if fitted is None:
        return None, 0
    beta, cov, dof = fitted
    out = {}
    for i, name in enumerate(names):
        if name.startswith("block"):
            continue
        low, high, p = interval(float(beta[i]), math.sqrt(max(cov[i, i], 0.0)), dof)
        out[name] = (float(beta[i]), low, high, p)
    return out, dof


def fit_random(runs, selectors):
    """Flights as a sample: the fit per sequence; per selector the mean effect over the
    sequences that could estimate it, its t-interval and p (None below two sequences)."""
    per_sequence = {s: [] for s in selectors}
    for dataset in unique(r["dataset"] for r in runs):
        here = [r for r in runs if r["dataset"] == dataset]
        present = [s for s in selectors if any(r["selector"] == s for r in here)]
        fitted = fit_fixed(here, present)[0]
        if fitted is None:
            continue
        for s in present:
            per_sequence[s].append(fitted[f"effect {s}"][0])
    out = {}
    for s, effects in per_sequence.items():
        if len(effects) < 2:
            out[s] = None
            continue
        m = float(np.mean(effects))
        se = float(np.std(effects, ddof=1)) / math.sqrt(len(effects))
        low, high, p = interval(m, se, len(effects) - 1)
        out[s] = (m, low, high, p, len(effects))
    return out


def pct(log_value):
    return paired_statistics.pct(log_value)


def fmt(v):
    return paired_statistics.fmt_pct(v)


def label(change, p_holm):
    if not math.isfinite(p_holm):
        return "not computed"
    if p_holm < ALPHA:
        return "significantly worse" if change > 0 else "significantly better"
    return "not distinguishable"


def analysis(runs, sensor, baseline):
    """Markdown lines of the regression for one sensor."""
    sub = [r for r in runs if r["sensor"] == sensor]
    used = [r for r in sub if r["ok"] and math.isfinite(r["rate"]) and r["rate"] > 0]
    left_out = len(sub) - len(used)
    selectors = [s for s in unique(r["selector"] for r in used) if s != baseline]
    if not any(r["selector"] == baseline for r in used):
        return [f"No successful {baseline} run ({sensor}): nothing to compare with."]
    fixed, dof = fit_fixed(used, selectors)
    if fixed is None:
        return [f"The runs of {sensor} do not separate the rate from the selectors (too few "
                "runs or rates): no fit."]
    random_ = fit_random(used, selectors)
    lines = [f"{len(used)} runs in the fit ({left_out} failed runs left out), residual degrees "
             f"of freedom {dof}.", "",
             "| sequence | slope of log ATE on log rate, 95% interval | ATE when the rate doubles |",
             "|---|---|---|"]
    for name, (b, low, high, p) in fixed.items():
        if name.startswith("slope "):
            lines.append(f"| {short(name[6:])} | {b:+.2f} [{low:+.2f}, {high:+.2f}], p {p:.2g} "
                         f"| {fmt(100 * (2 ** b - 1))} [{fmt(100 * (2 ** low - 1))}, "
                         f"{fmt(100 * (2 ** high - 1))}] |")
    fixed_p = paired_statistics.holm([fixed[f"effect {s}"][3] for s in selectors])
    random_p = paired_statistics.holm([random_[s][3] if random_[s] else math.nan
                                      for s in selectors])
    lines += ["", f"| selector vs {baseline} at the same keyframe rate | sequences fixed: ATE "
              "change, 95% interval, Holm p | verdict | flights as a sample: ATE change, 95% "
              "interval, Holm p | verdict |", "|---|---|---|---|---|"]
    for s, pf, pr in zip(selectors, fixed_p, random_p):
        b, low, high, _ = fixed[f"effect {s}"]
        cell_f = f"{fmt(pct(b))} [{fmt(pct(low))}, {fmt(pct(high))}], {pf:.3g}"
        r = random_[s]
        if r is None:
            cell_r, verdict_r = "fewer than two sequences", "not computed"
        else:
            cell_r = (f"{fmt(pct(r[0]))} [{fmt(pct(r[1]))}, {fmt(pct(r[2]))}], {pr:.3g} "
                      f"({r[4]} sequences)")
            verdict_r = label(r[0], pr)
        lines.append(f"| {s} | {cell_f} | {label(b, pf)} | {cell_r} | {verdict_r} |")
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("results", help="REPORT/results.csv of pkslam bench --collect of "
                        "bench/suites/pks-budget.yaml")
    parser.add_argument("--baseline", default="orbslam3",
                        help="the reference selector of the regression (default orbslam3)")
    parser.add_argument("--pool-builds", action="store_true",
                        help="analyse runs of different builds together (refused by default)")
    args = parser.parse_args()
    try:
        runs = read_runs(args.results)
    except (OSError, ValueError, KeyError) as e:
        sys.exit(f"budget_tables: {args.results}: {e}")
    mixed = bench_statistics.pooled_builds(runs)
    if mixed and not args.pool_builds:
        print(f"budget_tables: {args.results}: {mixed}; pass --pool-builds to analyse them "
              "together", file=sys.stderr)
        sys.exit(3)
    out = []
    for sensor in unique(r["sensor"] for r in runs):
        out += [f"### Equal keyframe budget, {sensor}", "",
                "**Per configuration** (keyframes created, culled ones too, per minute of "
                "sequence, mean over runs; ATE Sim(3))", ""]
        out += per_sequence_table(runs, sensor)
        out += ["", "**Rate and selector** (log ATE = rendering + slope(sequence) log rate + "
                "selector; failed runs left out)", ""]
        out += analysis(runs, sensor, args.baseline)
        out.append("")
    print("\n".join(out))


if __name__ == "__main__":
    main()
