#!/usr/bin/env bash
# The README's two commands timed as a new user meets them (issue 40): a fresh clone of REPO in
# WORK/clone and an empty ccache in WORK/ccache, then `scripts/demo` and `scripts/test` one after
# the other. Prints both times and ccache's statistics; logs in WORK/. The Debian packages are
# whatever this machine has (scripts/setup installs the missing ones, and that time is inside
# the first command's). WORK/shared links to the repository's ../shared, so the tests that need
# its data run (without it they skip and the second command is about 2 minutes shorter).
#   evaluation/studies/speed/first_hour.sh REPO WORK
set -euo pipefail
repo=$(realpath "$1"); work=$2
rm -rf "$work/clone" "$work/ccache"
mkdir -p "$work/ccache"
if [ -d "$repo/../shared" ] && [ ! -e "$work/shared" ]; then
  ln -s "$(realpath "$repo/../shared")" "$work/shared"
fi
git clone -q "$repo" "$work/clone"
work=$(realpath "$work")
cd "$work/clone"
export CCACHE_DIR=$work/ccache
unset CCACHE_BASEDIR
t0=$(date +%s)
scripts/demo > "$work/demo.log" 2>&1
t1=$(date +%s)
scripts/test > "$work/test.log" 2>&1
t2=$(date +%s)
echo "commit $(git rev-parse --short HEAD), $(nproc) cores"
echo "scripts/demo: $((t1 - t0)) s"
echo "scripts/test: $((t2 - t1)) s ($(grep -o 'Total Test time (real) = [0-9.]* sec' "$work/test.log"))"
echo "tests skipped: $(grep -c '\*\*\*Skipped' "$work/test.log" || true)"
ccache -s | grep -E "Hits|Misses" || true
