#!/usr/bin/env bash
# A run into an almost full 2 MB tmpfs (needs root for the mount): for each free-space level the
# run must exit 1 with one line naming the file it could not write, and leave the files written
# before it complete. Prints one line per level.
#   evaluation/studies/robustness/full_disk.sh [build/bin/pkslam]
set -euo pipefail
pkslam=$(realpath "${1:-build/bin/pkslam}")
work=$(mktemp -d)
mnt="$work/mnt"
mkdir -p "$mnt"
trap 'umount "$mnt" 2>/dev/null || true; rm -rf "$work"' EXIT
"$pkslam" --log-level warn simulate --out "$work/seq" --motion medium --duration 3 \
  --quality fast --quiet --no-cloud --seed 1 >/dev/null
mount -t tmpfs -o size=2m tmpfs "$mnt"
for free_kb in 4 12 20 40 80; do
  rm -rf "${mnt:?}"/*
  total_kb=$(df -k --output=avail "$mnt" | tail -1)
  dd if=/dev/zero of="$mnt/filler" bs=1k count=$((total_kb - free_kb)) status=none 2>/dev/null || true
  set +e
  out=$("$pkslam" run --dataset "$work/seq" --sensor stereo --quiet --out "$mnt/out" 2>&1)
  code=$?
  set -e
  error=$(grep '^pkslam: error' <<<"$out" || true)
  files=$(cd "$mnt/out" 2>/dev/null && ls | tr '\n' ' ')
  eval_ok="-"
  if [ -f "$mnt/out/trajectory.txt" ]; then
    if "$pkslam" eval --gt "$work/seq/mav0/state_groundtruth_estimate0/data.csv" \
         --est "$mnt/out/trajectory.txt" --body-from-camera "$mnt/out/body_from_camera.txt" \
         >/dev/null 2>&1; then eval_ok=yes; else eval_ok=NO; fi
  fi
  echo "free ${free_kb} kB: exit $code; ${error:-no error line}; trajectory evaluates: $eval_ok; files: $files"
done
