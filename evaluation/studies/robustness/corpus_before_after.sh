#!/usr/bin/env bash
# The bad-input corpus (tests/bad_inputs/corpus.py) against this tree's pkslam and an older
# commit's, in one sitting: prints both classifications and their totals.
#   evaluation/studies/robustness/corpus_before_after.sh [OLD_COMMIT] [WORK_DIR]
# Default OLD_COMMIT 948b9c3 (before issue 20). Builds the old commit in WORK_DIR/before
# (pkslam only, ~20 min on 2 cores); the corpus's base sequences are simulated by this tree.
set -euo pipefail
cd "$(dirname "$0")/../../.."
old=${1:-948b9c3}
work=$(realpath -m "${2:-/tmp/pkslam_corpus_before_after}")
python=/usr/bin/python3
mkdir -p "$work"
if [ ! -x "$work/before/build/bin/pkslam" ]; then
  git worktree add -f "$work/before" "$old" >/dev/null
  cmake -S "$work/before" -B "$work/before/build" -DPKSLAM_BUILD_TESTS=OFF \
    -DPKSLAM_BUILD_BENCHMARKS=OFF >/dev/null
  cmake --build "$work/before/build" -j"$(nproc)" --target pkslam >/dev/null
fi
[ -x build/bin/pkslam ] || scripts/build >/dev/null
$python tests/bad_inputs/corpus.py make --pkslam build/bin/pkslam --work "$work/corpus"
echo "== before ($old)"
$python tests/bad_inputs/corpus.py run --pkslam "$work/before/build/bin/pkslam" \
  --work "$work/corpus" --json "$work/before.json" | grep -E '^[a-z0-9_]+ +[a-z]+ |^totals' || true
echo "== after ($(git rev-parse --short HEAD))"
$python tests/bad_inputs/corpus.py run --pkslam build/bin/pkslam --work "$work/corpus" \
  --json "$work/after.json" | grep -E '^[a-z0-9_]+ +[a-z]+ |^totals' || true
