#!/usr/bin/python3
"""Statistics of a `pkslam bench` (Debian python3-scipy + python3-numpy): is a configuration
more accurate than the suite's baseline, and can this many runs tell?

Rules (docs/bench.md "Statistics"):
- Outcome of a run: it FAILS when pkslam or its evaluation failed, or its evaluated trajectory
  covers less than MIN_COVERAGE of the frames. A successful run's ATE is over its tracked part.
  Failure rate and coverage are reported beside the ATE; means are over successful runs.
- One test for every comparison, per sequence and pooled: the permutation test on ranks.
  Statistic: the mean over sequences of the rank-biserial effect (U / (n1 n2) - 1/2, failures
  ranked worse than every success); labels permuted within each sequence (exact when there are
  few arrangements, else 20,000 Monte Carlo draws). Per sequence it is the same test on one
  sequence, so a suite of one sequence gives one p for its comparison, not two. Unlike a
  signed-rank test over 5 sequence means (which cannot go below p = 0.0625) it uses every run.
  Holm's correction over the configurations compared with one baseline per sensor.
- ATE change, in the sign every part of the report uses: the mean over sequences of
  100 (mean ATE - mean ATE_base) / mean ATE_base, negative = lower error (the paper's "mean of
  per-sequence improvements" with its sign turned), with a bootstrap 95% interval (runs
  resampled within each sequence and configuration, 5,000 draws).
- Power: for the paper's effect (ATE x 0.819 stereo-inertial, x 0.796 mono-inertial, x 0.819
  otherwise) on log ATE with the observed within-sequence spread, the power of a two-sided 5%
  test at the present run count, and the runs per sequence that would give 80%; a missing
  effect is called "not reproduced" only with at least MIN_RUNS_FOR_VERDICT runs per sequence.
- One build: the runs of pkslam's configurations must come from one pkslam build (results.csv's
  pkslam_commit and executable) and each peer's runs from one peer build (peer_build); a file
  that pools several is refused (exit 3) unless --pool-builds says to analyse it anyway.

  /usr/bin/python3 bench/bench_statistics.py OUT/results.csv [--md FILE] [--html FILE]
      [--pool-builds]
"""

import argparse
import csv
import html
import itertools
import json
import math
import sys
from collections import OrderedDict

import numpy as np
from scipy import stats

import paired_statistics

MIN_COVERAGE = 0.5
ALPHA = paired_statistics.ALPHA
PAPER_RATIO = paired_statistics.PAPER_RATIO
BOOTSTRAP = 5000
# Fewer successful runs per sequence and configuration than this: the spread (and so the power)
# is too poorly known to call a missing effect "not reproduced".
MIN_RUNS_FOR_VERDICT = 5
PERMUTATIONS = 20000
PERMUTATION_SEED = 20000


def number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def read_rows(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    out = []
    for r in rows:
        if r.get("sweep_param"):
            continue  # sweeps are compared at equal budget in the plots, not tested here
        ate = number(r["ate_m"])
        coverage = number(r.get("coverage"))
        ok = r["status"] == "ok" and math.isfinite(ate) and not (
            math.isfinite(coverage) and coverage < MIN_COVERAGE)
        out.append({"dataset": r["dataset"], "sensor": r["sensor"], "config": r["config"],
                    "baseline": r["baseline"], "ok": ok, "ate": ate if ok else math.inf,
                    "coverage": coverage if math.isfinite(coverage) else 0.0,
                    "suspect": number(r.get("suspect")),
                    "build": build_of(r),
                    "seed": r.get("seed", ""),
                    "index": int(r["index"])})
    out.sort(key=lambda r: r["index"])
    return out


def build_of(r):
    """What made a run: the peer's build for a peer run, else pkslam's commit and executable
    ("" for files written before results.csv recorded them)."""
    if r.get("peer_build"):
        return "peer " + r["peer_build"]
    commit, executable = r.get("pkslam_commit") or "", r.get("executable") or ""
    return f"pkslam {commit} (executable {executable})" if commit or executable else ""


def pooled_builds(rows):
    """None when pkslam's configurations share one build and each peer one build; else a one-line
    reason naming the builds and their run counts."""
    groups = OrderedDict()  # "pkslam" or the peer configuration -> build -> runs
    for r in rows:
        owner = r["config"] if r["build"].startswith("peer ") else "pkslam"
        counts = groups.setdefault(owner, OrderedDict())
        counts[r["build"]] = counts.get(r["build"], 0) + 1
    problems = []
    for owner, counts in groups.items():
        if len(counts) > 1:
            listed = "; ".join(f"{b or 'not recorded'}: {n} runs" for b, n in counts.items())
            problems.append(f"{owner} runs come from {len(counts)} builds ({listed})")
    return "; ".join(problems) if problems else None


unique = paired_statistics.unique


def rank_biserial(a, b):
    """U / (n_a n_b) - 1/2 for 'a smaller than b' (positive: a more accurate). inf ties tie."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    less = (a[:, None] < b[None, :]).sum()
    ties = (a[:, None] == b[None, :]).sum()
    return (less + 0.5 * ties) / (a.size * b.size) - 0.5




def stratified_permutation(strata, seed=PERMUTATION_SEED):
    """strata: list of (a, b) ATE arrays. Two-sided p of the mean rank-biserial effect. The
    Monte Carlo draws come from their own generator, so the same runs give the same p wherever
    the comparison appears (a sequence's row and a one-sequence pooled line)."""
    rng = np.random.default_rng(seed)
    observed = np.mean([rank_biserial(a, b) for a, b in strata])
    pooled = [np.concatenate([a, b]) for a, b in strata]
    sizes = [len(a) for a, _ in strata]
    arrangements = 1
    for p, n in zip(pooled, sizes):
        arrangements *= math.comb(len(p), n)
    if arrangements <= PERMUTATIONS:
        per_stratum = []
        for p, n in zip(pooled, sizes):
            values = []
            for idx in itertools.combinations(range(len(p)), n):
                mask = np.zeros(len(p), dtype=bool)
                mask[list(idx)] = True
                values.append(rank_biserial(p[mask], p[~mask]))
            per_stratum.append(values)
        totals = np.array([np.mean(c) for c in itertools.product(*per_stratum)])
        exact = True
    else:
        totals = np.empty(PERMUTATIONS)
        for k in range(PERMUTATIONS):
            effects = []
            for p, n in zip(pooled, sizes):
                perm = rng.permutation(len(p))
                effects.append(rank_biserial(p[perm[:n]], p[perm[n:]]))
            totals[k] = np.mean(effects)
        exact = False
    extreme = np.sum(np.abs(totals) >= abs(observed) - 1e-12)
    p = extreme / totals.size if exact else (extreme + 1) / (totals.size + 1)
    return float(observed), float(p), exact


def ate_change(strata):
    """Mean over strata of 100 (mean config - mean base) / mean base over successful runs:
    negative = lower error."""
    values = []
    for a, b in strata:
        a = a[np.isfinite(a)]
        b = b[np.isfinite(b)]
        if a.size and b.size:
            values.append(100.0 * (a.mean() - b.mean()) / b.mean())
    return float(np.mean(values)) if values else math.nan


def bootstrap_interval(strata, rng):
    draws = []
    for _ in range(BOOTSTRAP):
        resampled = [(rng.choice(a, a.size), rng.choice(b, b.size)) for a, b in strata]
        v = ate_change(resampled)
        if math.isfinite(v):
            draws.append(v)
    if len(draws) < BOOTSTRAP // 2:
        return math.nan, math.nan
    return float(np.percentile(draws, 2.5)), float(np.percentile(draws, 97.5))


def identical(strata):
    """True when every configuration's successful runs in every stratum gave one ATE."""
    groups = [g[np.isfinite(g)] for pair in strata for g in pair]
    return all(g.size > 1 and np.all(g == g[0]) for g in groups)


holm = paired_statistics.holm  # one Holm for both analyses


def log_spread(strata):
    """Pooled within-group standard deviation of log ATE (successful runs) and runs per group."""
    ss, dof, counts = 0.0, 0, []
    for a, b in strata:
        for g in (a, b):
            g = np.log(g[np.isfinite(g)])
            counts.append(g.size)
            if g.size > 1:
                ss += float(((g - g.mean()) ** 2).sum())
                dof += g.size - 1
    sigma = math.sqrt(ss / dof) if dof > 0 else math.nan
    return sigma, (float(np.mean(counts)) if counts else 0.0)


def power(effect, sigma, runs, strata):
    """Power of a two-sided 5% z-test of the stratified mean log-ATE difference."""
    if not (math.isfinite(sigma) and sigma > 0 and runs > 0 and strata > 0):
        return math.nan
    se = sigma * math.sqrt(2.0 / (runs * strata))
    z = stats.norm.ppf(1 - ALPHA / 2)
    shift = abs(effect) / se
    return float(stats.norm.cdf(shift - z) + stats.norm.cdf(-shift - z))


def runs_for_power(effect, sigma, strata, target=0.8):
    if not (math.isfinite(sigma) and sigma > 0 and effect != 0):
        return math.nan
    z = stats.norm.ppf(1 - ALPHA / 2) + stats.norm.ppf(target)
    return math.ceil(2.0 * (z * sigma / effect) ** 2 / strata)


def has_pairs(rows):
    """True when some sequence's seed was run by more than one configuration (run k of every
    configuration shares its rendering and seed: the paired design)."""
    seen = {}
    for r in rows:
        if r.get("seed", "") == "":
            continue
        seen.setdefault((r["dataset"], r["sensor"], r["seed"]), set()).add(r["config"])
    return any(len(configs) > 1 for configs in seen.values())


def analyse(rows, seed=1, pairs=None):
    """The unpaired tests below, and the paired analysis (paired_statistics.py) when the runs
    are pairs; `pairs`: the (config, baseline) comparisons, default each one against the suite's
    baseline."""
    result = analyse_unpaired(rows, seed)
    if has_pairs(rows):
        result["paired"] = paired_statistics.analyse(rows, pairs)
    return result


def analyse_unpaired(rows, seed=1):
    rng = np.random.default_rng(seed)
    result = {"rules": {"min_coverage": MIN_COVERAGE, "alpha": ALPHA}, "outcomes": [],
              "per_sequence": [], "pooled": []}
    for key in unique((r["dataset"], r["sensor"], r["config"]) for r in rows):
        g = [r for r in rows if (r["dataset"], r["sensor"], r["config"]) == key]
        ok = [r["ate"] for r in g if r["ok"]]
        result["outcomes"].append({
            "dataset": key[0], "sensor": key[1], "config": key[2], "runs": len(g),
            "failures": len(g) - len(ok), "failure_rate": (len(g) - len(ok)) / len(g),
            "coverage": float(np.mean([r["coverage"] for r in g])),
            # Successful runs whose own signals call the estimate suspect (a loss for good):
            # None when the results predate the flag.
            "suspect": (sum(1 for r in g if r["ok"] and r.get("suspect") == 1)
                        if any(math.isfinite(r.get("suspect", math.nan)) for r in g) else None),
            "ate_mean": float(np.mean(ok)) if ok else math.nan,
            "ate_std": float(np.std(ok, ddof=1)) if len(ok) > 1 else math.nan,
            "identical": len(ok) > 1 and all(v == ok[0] for v in ok)})
    for sensor in unique(r["sensor"] for r in rows):
        sub = [r for r in rows if r["sensor"] == sensor]
        baseline = sub[0]["baseline"]
        configs = [c for c in unique(r["config"] for r in sub) if c != baseline]
        pooled = []
        for config in configs:
            strata = []
            for dataset in unique(r["dataset"] for r in sub):
                a = np.array([r["ate"] for r in sub if r["dataset"] == dataset
                              and r["config"] == config])
                b = np.array([r["ate"] for r in sub if r["dataset"] == dataset
                              and r["config"] == baseline])
                if a.size == 0 or b.size == 0:
                    continue
                strata.append((a, b))
                ci = bootstrap_interval([(a, b)], rng)
                effect, p, exact = stratified_permutation([(a, b)])
                result["per_sequence"].append({
                    "dataset": dataset, "sensor": sensor, "config": config, "baseline": baseline,
                    "runs": int(a.size), "baseline_runs": int(b.size),
                    "ate_change_pct": ate_change([(a, b)]), "ci_low": ci[0], "ci_high": ci[1],
                    "effect": effect, "p": p, "exact": exact, "identical": identical([(a, b)])})
            if not strata:
                continue
            effect, p, exact = stratified_permutation(strata)
            ci = bootstrap_interval(strata, rng)
            sigma, runs = log_spread(strata)
            changes = [ate_change([stratum]) for stratum in strata]
            changes = [c for c in changes if math.isfinite(c)] or [math.nan]
            paper = math.log(PAPER_RATIO.get(sensor, 1 - 0.181))
            pooled.append({
                "sensor": sensor, "config": config, "baseline": baseline,
                "sequences": len(strata), "runs_per_sequence": runs,
                "ate_change_pct": ate_change(strata), "ci_low": ci[0], "ci_high": ci[1],
                "effect": effect, "p": p, "exact": exact, "sigma_log": sigma,
                "identical": identical(strata),
                "sequence_change_min_pct": min(changes), "sequence_change_max_pct": max(changes),
                "paper_change_pct": 100 * (math.exp(paper) - 1),
                "power_for_paper": power(paper, sigma, runs, len(strata)),
                "runs_for_80pct_power": runs_for_power(paper, sigma, len(strata))})
        for entry, adjusted in zip(pooled, holm([e["p"] for e in pooled])):
            entry["p_holm"] = adjusted
            entry["sentence"] = sentence(entry)
        result["pooled"].extend(pooled)
    return result


def sentence(e):
    seqs = f"{e['sequences']} sequence" + ("s" if e["sequences"] != 1 else "")
    head = (f"{e['config']} vs {e['baseline']} ({e['sensor']}, {seqs}, "
            f"~{e['runs_per_sequence']:.0f} runs each): ATE change {fmt_pct(e['ate_change_pct'])} "
            f"[95% CI {fmt_pct(e['ci_low'])}, {fmt_pct(e['ci_high'])}], "
            f"permutation test on ranks p = {e['p']:.3g}, Holm p = {e['p_holm']:.3g}")
    paper = f"the paper's {fmt_pct(e['paper_change_pct'])}"
    if e.get("identical"):
        return (f"{head}: every run of each configuration gave the same ATE (deterministic "
                f"runs), so there is no run-to-run spread to test against: the change holds for "
                f"this rendering and seed only.")
    if e["p_holm"] < ALPHA:
        direction = "more accurate" if e["effect"] > 0 else "less accurate"
        if (math.isfinite(e["ci_low"]) and math.isfinite(e["ci_high"]) and
                e["ci_low"] <= 0 <= e["ci_high"]):
            # The converse parting: ranks agree across most sequences, while a few large
            # relative changes move the mean either way.
            head += (f" (the rank test rejects but the interval on the mean change includes 0; "
                     f"per-sequence changes {fmt_pct(e['sequence_change_min_pct'])} to "
                     f"{fmt_pct(e['sequence_change_max_pct'])})")
        inside = (math.isfinite(e["ci_low"]) and
                  e["ci_low"] <= e["paper_change_pct"] <= e["ci_high"])
        return (f"{head}: significantly {direction} than {e['baseline']}; {paper} lies "
                f"{'inside' if inside else 'outside'} the interval.")
    pw = e["power_for_paper"]
    # The interval is on the paper's mean relative change, the test on ranks: they can part when
    # the sequences disagree in sign or a few runs' sizes carry the mean. Say so, not hide it.
    if (math.isfinite(e["ci_low"]) and math.isfinite(e["ci_high"]) and
            (e["ci_low"] > 0 or e["ci_high"] < 0)):
        head += (f" (the interval on the mean change excludes 0 but the rank test does not; "
                 f"per-sequence changes {fmt_pct(e['sequence_change_min_pct'])} to "
                 f"{fmt_pct(e['sequence_change_max_pct'])})")
    if math.isfinite(pw) and pw >= 0.8 and e["runs_per_sequence"] >= MIN_RUNS_FOR_VERDICT:
        return (f"{head}: no significant difference, and an effect of {paper} would have been "
                f"found with power {pw:.0%}: not reproduced at this setting.")
    if e["runs_per_sequence"] < MIN_RUNS_FOR_VERDICT:
        return (f"{head}: not decidable: fewer than {MIN_RUNS_FOR_VERDICT} runs per sequence "
                f"(a verdict needs at least that many, whatever the power).")
    need = e["runs_for_80pct_power"]
    need_text = f"about {need} runs per sequence" if math.isfinite(need) else "more runs"
    pw_text = f"{pw:.0%}" if math.isfinite(pw) else "unknown"
    return (f"{head}: not decidable at this run count (power {pw_text} for {paper}; "
            f"{need_text} would give 80%).")


def fmt_pct(v):
    return "n/a" if not math.isfinite(v) else f"{v:+.1f}%"


def fmt(v, digits=4):
    return "—" if not (isinstance(v, (int, float)) and math.isfinite(v)) else f"{v:.{digits}f}"


def mean_std_text(o):
    """ATE mean ± std of an outcome; one run or identical runs say so (a zero spread of
    deterministic runs is not a measured spread)."""
    ok = o["runs"] - o["failures"]
    if ok == 1:
        return f"{fmt(o['ate_mean'])} (1 run)"
    if ok > 1 and o.get("identical"):
        return f"{fmt(o['ate_mean'])} ({ok} identical runs)"
    return f"{fmt(o['ate_mean'])} ± {fmt(o['ate_std'])}"


def tables(result):
    """(title, header, rows) tables of the analysis."""
    out = []
    out.append(("Outcomes: failure rate and coverage beside the ATE (mean ± std over successful "
                "runs)", ["dataset", "sensor", "config", "runs", "failed", "suspect", "coverage",
                          "ATE [m]"],
                [[o["dataset"], o["sensor"], o["config"], str(o["runs"]),
                  f"{o['failures']} ({o['failure_rate']:.0%})",
                  "—" if o.get("suspect") is None else str(o["suspect"]), f"{o['coverage']:.1%}",
                  mean_std_text(o)] for o in result["outcomes"]]))
    out.append(("Per sequence: permutation test on ranks against the baseline (failures ranked "
                "worst)",
                ["dataset", "sensor", "config", "ATE change", "95% CI", "effect", "p"],
                [[s["dataset"], s["sensor"], s["config"], fmt_pct(s["ate_change_pct"]),
                  f"{fmt_pct(s['ci_low'])} … {fmt_pct(s['ci_high'])}", f"{s['effect']:+.2f}",
                  "identical runs" if s.get("identical") else f"{s['p']:.3g}"]
                 for s in result["per_sequence"]]))
    out.append(("Pooled over sequences: the same permutation test, stratified by sequence, "
                "Holm-corrected",
                ["sensor", "config", "ATE change", "95% CI", "p", "Holm p",
                 "power for paper", "runs for 80%"],
                [[e["sensor"], e["config"], fmt_pct(e["ate_change_pct"]),
                  f"{fmt_pct(e['ci_low'])} … {fmt_pct(e['ci_high'])}",
                  "identical runs" if e.get("identical") else f"{e['p']:.3g}",
                  "—" if e.get("identical") else f"{e['p_holm']:.3g}",
                  "—" if not math.isfinite(e["power_for_paper"]) else f"{e['power_for_paper']:.0%}",
                  "—" if not math.isfinite(e["runs_for_80pct_power"])
                  else str(e["runs_for_80pct_power"])] for e in result["pooled"]]))
    return out


RULES = ("A run fails when pkslam or its evaluation failed or its trajectory covers less than "
         f"{MIN_COVERAGE:.0%} of the frames; a successful run's ATE is over its tracked part. "
         "Suspect: successful runs that flagged their own estimate (tracking lost for good; "
         "stats.json \"estimate\"); they stay in the ATE. "
         "ATE change = mean over sequences of 100 (ATE - ATE_base) / ATE_base, negative = lower "
         "error (the sign of every table above); 95% CI by bootstrap over runs; effect = "
         "rank-biserial (positive = more accurate); one test for every comparison, the "
         "permutation test on ranks, two-sided at 5%.")


def markdown(result):
    lines = ["Rules: " + RULES, ""]
    for e in result["pooled"]:
        lines.append("- " + e["sentence"])
    lines.append("")
    for title, header, rows in tables(result):
        lines += [f"**{title}**", "", "| " + " | ".join(header) + " |",
                  "|" + "---|" * len(header)]
        lines += ["| " + " | ".join(r) + " |" for r in rows]
        lines.append("")
    if "paired" in result:
        lines.append(paired_statistics.markdown(result["paired"]))
    return "\n".join(lines) + "\n"


def html_fragment(result):
    parts = [f"<p>Rules: {html.escape(RULES)}</p>", "<ul>"]
    parts += [f"<li>{html.escape(e['sentence'])}</li>" for e in result["pooled"]]
    parts.append("</ul>")
    for title, header, rows in tables(result):
        parts.append(f"<p><b>{html.escape(title)}</b></p><table><tr>"
                     + "".join(f"<th>{html.escape(h)}</th>" for h in header) + "</tr>")
        for r in rows:
            parts.append("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>")
        parts.append("</table>")
    if "paired" in result:  # the Markdown tables, preformatted
        parts.append("<pre>" + html.escape(paired_statistics.markdown(result["paired"])) + "</pre>")
    return "\n".join(parts) + "\n"


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("results")
    p.add_argument("--md", help="write the Markdown fragment here (default: stdout)")
    p.add_argument("--html", help="write the HTML fragment here")
    p.add_argument("--json", help="write the numbers here")
    p.add_argument("--compare", action="append", metavar="CONFIG:BASELINE",
                   help="a paired comparison (repeatable; default: each configuration against "
                        "the suite's baseline)")
    p.add_argument("--pool-builds", action="store_true",
                   help="analyse runs of different builds together (refused by default)")
    a = p.parse_args()
    rows = read_rows(a.results)
    if not rows:
        print("no runs", file=sys.stderr)
        return 1
    mixed = pooled_builds(rows)
    if mixed and not a.pool_builds:
        print(f"bench_statistics.py: {a.results}: {mixed}; analyse one build at a time, or pass "
              "--pool-builds", file=sys.stderr)
        return 3
    pairs = None
    if a.compare:
        try:
            pairs = paired_statistics.parse_pairs(a.compare)
        except ValueError:
            print("bench_statistics.py: --compare takes CONFIG:BASELINE", file=sys.stderr)
            return 2
    result = analyse(rows, pairs=pairs)
    md = markdown(result)
    if a.md:
        with open(a.md, "w") as f:
            f.write(md)
    else:
        sys.stdout.write(md)
    if a.html:
        with open(a.html, "w") as f:
            f.write(html_fragment(result))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(result, f, indent=1, default=float)
    return 0


if __name__ == "__main__":
    sys.exit(main())
