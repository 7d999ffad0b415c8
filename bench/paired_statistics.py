#!/usr/bin/python3
"""The paired analysis of a bench (issue 39; part of bench_statistics.py's report).

In a study whose run k of every configuration replays the same rendering with the same seed
(`seed_per_run` suites), runs are pairs: the comparison of a configuration with its baseline is
made within each pair, on log ATE (a ratio, as the paper's per-cent changes are).

- A pair is (sequence, seed) run by both. A failed run (bench_statistics.py's rule) counts as
  worse than every success: its log ATE is the sequence's worst successful log ATE + log 2.
- Fixed sequences (the sequences are the population): the statistic is the mean over sequences
  of the mean paired difference d = log ATE - log ATE_base; its p comes from a sign-flip
  permutation of the pairs (exact up to 2^16 arrangements, else 20,000 draws); its interval is a
  t-interval with the pooled within-sequence spread of d.
- Random sequences (the sequences are a sample of flights): the per-sequence mean differences
  are the observations, a one-sample t-test and t-interval over them (S - 1 degrees of freedom).
  This is what a claim about "EuRoC flights" rests on; with few sequences it is wide.
- Changes are reported as 100 (exp(d) - 1) per cent, negative = lower error; Holm over the
  comparisons of one sensor, separately for each analysis.
- Verdict labels, one set for every comparison: "significantly better" / "significantly worse"
  (Holm p < 0.05) or "not distinguishable"; and "the paper's effect lies outside the interval"
  when the paper's change (-18.1% stereo-inertial, -20.4% mono-inertial) is outside the 95%
  interval. Each verdict is scoped to what ran: realistic renders of the EuRoC trajectories.
- Power, per analysis: the probability that a t-test at 0.05 (unadjusted; the fixed analysis's
  sign flip is approximated by its t-interval) with the spread measured here finds the paper's
  change, and the smallest reduction it finds with 80% probability. A "not distinguishable"
  with low power says little; with high power it says the paper's effect is not there.
"""

import itertools
import math
import re
from collections import OrderedDict

import numpy as np
from scipy import optimize, stats

ALPHA = 0.05
PAPER_RATIO = {"stereo-inertial": 1 - 0.181, "mono-inertial": 1 - 0.204}
FAILED_PENALTY = math.log(2.0)
EXACT_LIMIT = 16  # pairs: exact sign-flip enumeration up to 2^16 arrangements
PERMUTATIONS = 20000
PERMUTATION_SEED = 39
MAX_NONCENTRALITY = 60.0

# The paper's per-sequence mean ATE (m), ORB-SLAM3 / PKS (../shared/docs/PKS.md).
PAPER_SEQUENCES = {
    "stereo-inertial": {"MH01": (.037, .031), "MH02": (.032, .028), "MH03": (.028, .029),
                        "MH04": (.061, .048), "MH05": (.091, .063), "V101": (.037, .036),
                        "V102": (.015, .013), "V103": (.024, .023), "V201": (.037, .030),
                        "V202": (.016, .015), "V203": (.036, .023)},
    "mono-inertial": {"MH01": (.035, .019), "MH02": (.063, .041), "MH03": (.033, .030),
                      "MH04": (.100, .068), "MH05": (.072, .064), "V101": (.044, .042),
                      "V102": (.018, .018), "V103": (.031, .030), "V201": (.042, .043),
                      "V202": (.016, .017), "V203": (.038, .018)},
}


def unique(values):
    return list(OrderedDict.fromkeys(values))


def paper_key(dataset):
    """'real_MH_01_easy', 'V1_02_all', 'MH01' -> 'MH01' / 'V102'; None when not a EuRoC name."""
    m = re.search(r"(MH|V1|V2)_?0?([1-5])", dataset)
    return f"{m.group(1)}0{m.group(2)}" if m else None


def paper_change_pct(sensor, dataset):
    pair = PAPER_SEQUENCES.get(sensor, {}).get(paper_key(dataset) or "")
    return 100.0 * (pair[1] / pair[0] - 1.0) if pair else math.nan


def paired_differences(rows, sensor, config, baseline):
    """OrderedDict dataset -> array of paired log-ATE differences (config - baseline)."""
    sub = [r for r in rows if r["sensor"] == sensor]
    out = OrderedDict()
    for dataset in unique(r["dataset"] for r in sub):
        here = [r for r in sub if r["dataset"] == dataset]
        finite = [r["ate"] for r in here if r["ok"]]
        if not finite:
            continue  # every run failed: nothing to scale a failure by
        failed = math.log(max(finite)) + FAILED_PENALTY

        def log_ate(r):
            return math.log(r["ate"]) if r["ok"] else failed

        a = {r["seed"]: log_ate(r) for r in here if r["config"] == config}
        b = {r["seed"]: log_ate(r) for r in here if r["config"] == baseline}
        seeds = sorted(set(a) & set(b))
        if seeds:
            out[dataset] = np.array([a[s] - b[s] for s in seeds])
    return out


def statistic(diffs):
    return float(np.mean([d.mean() for d in diffs]))


def sign_flip_p(diffs, seed=PERMUTATION_SEED):
    """Two-sided p of the mean over sequences of the mean paired difference under random
    signs; (p, exact)."""
    observed = abs(statistic(diffs))
    flat = np.concatenate(diffs)
    weights = np.concatenate([np.full(d.size, 1.0 / (d.size * len(diffs))) for d in diffs])
    values = flat * weights
    if flat.size <= EXACT_LIMIT:
        signs = np.array(list(itertools.product((1.0, -1.0), repeat=flat.size)))
        totals = np.abs(signs @ values)
        return float(np.mean(totals >= observed - 1e-12)), True
    rng = np.random.default_rng(seed)
    signs = rng.choice((1.0, -1.0), size=(PERMUTATIONS, flat.size))
    extreme = int(np.sum(np.abs(signs @ values) >= observed - 1e-12))
    return (extreme + 1) / (PERMUTATIONS + 1), False


def fixed_spread(diffs):
    """(standard error, degrees of freedom) of the statistic with the sequences fixed: the
    pooled within-sequence spread of the differences."""
    dof = sum(d.size - 1 for d in diffs)
    if dof <= 0:
        return math.nan, 0
    ss = sum(float(((d - d.mean()) ** 2).sum()) for d in diffs)
    return math.sqrt(ss / dof * sum(1.0 / d.size for d in diffs)) / len(diffs), dof


def random_spread(diffs):
    """(standard error, degrees of freedom) of the mean of the per-sequence mean differences."""
    means = np.array([d.mean() for d in diffs])
    if means.size < 2:
        return math.nan, 0
    return float(means.std(ddof=1)) / math.sqrt(means.size), means.size - 1


def fixed_interval(diffs):
    """95% t-interval of the statistic with the sequences fixed."""
    se, dof = fixed_spread(diffs)
    if dof <= 0:
        return math.nan, math.nan
    half = stats.t.ppf(1 - ALPHA / 2, dof) * se
    m = statistic(diffs)
    return m - half, m + half


def random_sequences(diffs):
    """(p, low, high) of a one-sample t-test over the per-sequence mean differences."""
    se, dof = random_spread(diffs)
    if dof <= 0:
        return math.nan, math.nan, math.nan
    m = float(np.mean([d.mean() for d in diffs]))
    if se == 0:
        return (1.0 if m == 0 else 0.0), m, m
    p = 2 * float(stats.t.sf(abs(m / se), dof))
    half = stats.t.ppf(1 - ALPHA / 2, dof) * se
    return p, m - half, m + half


def power(effect, se, dof):
    """Probability that a two-sided t-test at ALPHA with this standard error and these degrees
    of freedom finds a true log-ratio `effect` (noncentral t). The spread is the one measured,
    the effect a hypothesis (the paper's), so this is the design's power for that effect, not
    the "observed power" of the measured change."""
    if dof <= 0 or not math.isfinite(se):
        return math.nan
    if se == 0:
        return 1.0 if effect != 0 else ALPHA
    crit = stats.t.ppf(1 - ALPHA / 2, dof)
    # Beyond 60 standard errors the power is 1 to many digits; scipy's noncentral t fails there.
    nc = max(-MAX_NONCENTRALITY, min(MAX_NONCENTRALITY, effect / se))
    with np.errstate(divide="ignore"):  # a tail far beyond the critical value is 0
        return float(stats.nct.sf(crit, dof, nc) + stats.nct.cdf(-crit, dof, nc))


def detectable_pct(se, dof, target=0.8):
    """The smallest reduction (per cent, negative) found with probability `target`."""
    if dof <= 0 or not math.isfinite(se):
        return math.nan
    if se == 0:
        return 0.0
    # Solved in standard errors, where the bracket does not depend on the spread.
    nc = optimize.brentq(lambda n: power(-n, 1.0, dof) - target, 0.0, MAX_NONCENTRALITY)
    return pct(-nc * se)


def pct(log_value):
    return 100.0 * (math.exp(log_value) - 1.0) if math.isfinite(log_value) else math.nan


def holm(pvalues):
    """Holm-adjusted p-values (same order) over the comparisons that have one."""
    order = sorted((i for i, p in enumerate(pvalues) if not math.isnan(p)),
                   key=lambda i: pvalues[i])
    adjusted = [math.nan] * len(pvalues)
    running = 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (len(order) - rank) * pvalues[i]))
        adjusted[i] = running
    return adjusted


def verdict(change, p_holm, low, high, paper):
    """The labels of one analysis: direction (or none) and where the paper's effect lies."""
    if not math.isfinite(low):
        return ["not computed (too few sequences or pairs)"]
    labels = []
    if math.isfinite(p_holm) and p_holm < ALPHA:
        labels.append("significantly worse" if change > 0 else "significantly better")
    else:
        labels.append("not distinguishable")
    if math.isfinite(low) and not (low <= paper <= high):
        labels.append("the paper's effect lies outside the interval")
    return labels


def parse_pairs(texts):
    """["A:B", "C:D,E:F", ...] -> [(A, B), (C, D), (E, F)]; ValueError on anything else."""
    pairs = [tuple(item.split(":", 1)) for text in texts for item in text.split(",")]
    if not pairs or any(len(p) != 2 or not all(p) for p in pairs):
        raise ValueError("expected A:B[,C:D...]")
    return pairs


def comparisons_of(rows, sensor, pairs=None):
    """[(config, baseline)]: the given pairs that ran on this sensor, else every configuration
    against the suite's baseline."""
    sub = [r for r in rows if r["sensor"] == sensor]
    configs = unique(r["config"] for r in sub)
    if pairs:
        return [(c, b) for c, b in pairs if c in configs and b in configs]
    baseline = sub[0]["baseline"]
    return [(c, baseline) for c in configs if c != baseline]


def analyse(rows, pairs=None, seed=PERMUTATION_SEED):
    """{'per_sequence': [...], 'pooled': [...]} for every comparison of every sensor."""
    out = {"per_sequence": [], "pooled": []}
    for sensor in unique(r["sensor"] for r in rows):
        paper = math.log(PAPER_RATIO.get(sensor, 1 - 0.181))
        pooled = []
        for config, baseline in comparisons_of(rows, sensor, pairs):
            diffs = paired_differences(rows, sensor, config, baseline)
            if not diffs:
                continue
            for dataset, d in diffs.items():
                p, exact = sign_flip_p([d], seed)
                low, high = fixed_interval([d])
                out["per_sequence"].append({
                    "sensor": sensor, "dataset": dataset, "config": config, "baseline": baseline,
                    "pairs": int(d.size), "change_pct": pct(float(d.mean())),
                    "ci_low_pct": pct(low), "ci_high_pct": pct(high), "p": p, "exact": exact,
                    "paper_change_pct": paper_change_pct(sensor, dataset)})
            values = list(diffs.values())
            m = statistic(values)
            p_fixed, exact = sign_flip_p(values, seed)
            f_low, f_high = fixed_interval(values)
            p_random, r_low, r_high = random_sequences(values)
            f_se, f_dof = fixed_spread(values)
            r_se, r_dof = random_spread(values)
            pooled.append({
                "sensor": sensor, "config": config, "baseline": baseline,
                "sequences": len(values), "pairs": int(sum(d.size for d in values)),
                "change_pct": pct(m), "paper_change_pct": pct(paper),
                "fixed": {"p": p_fixed, "exact": exact, "low": f_low, "high": f_high,
                          "ci_low_pct": pct(f_low), "ci_high_pct": pct(f_high),
                          "power_paper": power(paper, f_se, f_dof),
                          "detectable_pct": detectable_pct(f_se, f_dof)},
                "random": {"p": p_random, "low": r_low, "high": r_high,
                           "ci_low_pct": pct(r_low), "ci_high_pct": pct(r_high),
                           "power_paper": power(paper, r_se, r_dof),
                           "detectable_pct": detectable_pct(r_se, r_dof)}})
        for kind in ("fixed", "random"):
            for entry, adjusted in zip(pooled, holm([e[kind]["p"] for e in pooled])):
                a = entry[kind]
                a["p_holm"] = adjusted
                a["verdict"] = verdict(math.log1p(entry["change_pct"] / 100.0), adjusted,
                                       a["low"], a["high"], paper)
        out["pooled"].extend(pooled)
    return out


def fmt_pct(v):
    return f"{v:+.1f}%" if math.isfinite(v) else "n/a"


def fmt_share(v):
    return f"{100 * v:.0f}%" if math.isfinite(v) else "n/a"


def fmt_p(v):
    return f"{v:.3g}" if math.isfinite(v) else "n/a"


def sentence(e):
    """One sentence per comparison, scoped to what ran."""
    f, r = e["fixed"], e["random"]
    trajectories = "trajectory" if e["sequences"] == 1 else "trajectories"
    return (f"On realistic renders of {e['sequences']} EuRoC {trajectories} ({e['sensor']}, "
            f"{e['pairs']} paired runs), {e['config']} vs {e['baseline']}: ATE "
            f"{fmt_pct(e['change_pct'])}; these sequences fixed: 95% interval "
            f"[{fmt_pct(f['ci_low_pct'])}, {fmt_pct(f['ci_high_pct'])}], Holm p "
            f"{fmt_p(f['p_holm'])} ({'; '.join(f['verdict'])}); flights as a sample: "
            f"[{fmt_pct(r['ci_low_pct'])}, {fmt_pct(r['ci_high_pct'])}], Holm p "
            f"{fmt_p(r['p_holm'])} ({'; '.join(r['verdict'])}). The paper: "
            f"{fmt_pct(e['paper_change_pct'])} on real EuRoC; the power to find it here: "
            f"{fmt_share(f['power_paper'])} with these sequences fixed, "
            f"{fmt_share(r['power_paper'])} with flights as a sample.")


def markdown(result):
    if not result["pooled"]:
        return ""
    lines = ["### Paired analysis (run k of every configuration shares its rendering and seed)",
             "",
             "| sensor | comparison | sequences | pairs | ATE change | fixed sequences: 95% "
             "interval, Holm p | verdict | flights as a sample: 95% interval, Holm p | "
             "verdict | paper |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for e in result["pooled"]:
        f, r = e["fixed"], e["random"]
        lines.append(
            f"| {e['sensor']} | {e['config']} vs {e['baseline']} | {e['sequences']} | "
            f"{e['pairs']} | {fmt_pct(e['change_pct'])} | [{fmt_pct(f['ci_low_pct'])}, "
            f"{fmt_pct(f['ci_high_pct'])}], {fmt_p(f['p_holm'])} | {'; '.join(f['verdict'])} | "
            f"[{fmt_pct(r['ci_low_pct'])}, {fmt_pct(r['ci_high_pct'])}], {fmt_p(r['p_holm'])} | "
            f"{'; '.join(r['verdict'])} | {fmt_pct(e['paper_change_pct'])} |")
    lines += ["", "Power: the probability that each analysis finds the paper's change, given the "
              "spread measured here; and the smallest reduction it finds with 80% probability.",
              "", "| sensor | comparison | the paper's change | fixed sequences: power, "
              "detectable | flights as a sample: power, detectable |", "|---|---|---|---|---|"]
    for e in result["pooled"]:
        f, r = e["fixed"], e["random"]
        lines.append(
            f"| {e['sensor']} | {e['config']} vs {e['baseline']} | "
            f"{fmt_pct(e['paper_change_pct'])} | {fmt_share(f['power_paper'])}, "
            f"{fmt_pct(f['detectable_pct'])} | {fmt_share(r['power_paper'])}, "
            f"{fmt_pct(r['detectable_pct'])} |")
    lines += ["", "| sensor | sequence | comparison | pairs | ATE change [95% interval] | p "
              "(sign flip) | the paper's change |", "|---|---|---|---|---|---|---|"]
    for e in result["per_sequence"]:
        lines.append(
            f"| {e['sensor']} | {e['dataset']} | {e['config']} vs {e['baseline']} | {e['pairs']} "
            f"| {fmt_pct(e['change_pct'])} [{fmt_pct(e['ci_low_pct'])}, "
            f"{fmt_pct(e['ci_high_pct'])}] | {fmt_p(e['p'])} | {fmt_pct(e['paper_change_pct'])} |")
    lines += [""] + [f"- {sentence(e)}" for e in result["pooled"]]
    return "\n".join(lines) + "\n"
