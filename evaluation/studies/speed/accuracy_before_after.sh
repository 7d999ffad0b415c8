#!/usr/bin/env bash
# Accuracy before/after a change, on the same renders: the smoke suite and a subset of
# sim-euroc (selectors orbslam3 and pks, runs with seeds 1 and 2, no delta sweep), run once with
# a previous build of pkslam (OLD, e.g. the parent commit built into another folder) and once
# with this checkout's build/bin/pkslam. The simulator is seeded, so both render identical
# sequences (the bench keys its render cache by executable, so each renders its own copy).
#   evaluation/studies/speed/accuracy_before_after.sh OLD_PKSLAM OUT
# Prints the headline ATE table of each report; the reports are OUT/{before,after}-*/report.md.
set -euo pipefail
root=$(cd "$(dirname "$0")/../../.." && pwd)
old=${1:?usage: accuracy_before_after.sh OLD_PKSLAM OUT}
out=${2:?usage: accuracy_before_after.sh OLD_PKSLAM OUT}
new=$root/build/bin/pkslam
suite=$root/bench/suites/sim-euroc.yaml
mapfile -t ids < <("$new" bench "$suite" --list | grep -v -e pks-released -e '@' -e seed3)
for which in before after; do
  exe=$new
  [ "$which" = before ] && exe=$old
  "$new" bench "$root/bench/suites/smoke.yaml" --out "$out/$which-smoke" --pkslam "$exe" --quiet --no-plots
  "$new" bench "$suite" --out "$out/$which-sim-euroc" --pkslam "$exe" --run-id "${ids[@]}" --quiet
  "$new" bench --out "$out/$which-sim-euroc" --collect "$out/$which-sim-euroc" --quiet --no-plots
done
for r in "$out"/*/results.csv; do
  echo "== $r"
  /usr/bin/python3 - "$r" <<'PY'
import csv, collections, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
by = collections.defaultdict(list)
fails = collections.Counter()
for r in rows:
    key = (r['dataset'], r['sensor'], r['config'])
    if r['status'] == 'ok':
        by[key].append(float(r['ate_m']))
    else:
        fails[key] += 1
for key in sorted(set(by) | set(fails)):
    v = by.get(key, [])
    print(*key, 'ate_mm mean %.2f' % (1e3 * statistics.mean(v)) if v else 'no ok run', 'runs', len(v), 'failed', fails[key])
allv = [x for v in by.values() for x in v]
print('overall mean ATE %.2f mm over %d ok runs, %d failed' % (1e3 * statistics.mean(allv), len(allv), sum(fails.values())))
PY
done
