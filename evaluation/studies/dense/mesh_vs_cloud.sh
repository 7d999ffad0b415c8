#!/bin/bash
# Issue 25's mesh measurement: a 40 s stereo replay of V1_02 (from 5 s; ../shared ground truth),
# a stereo run, then `pkslam dense` three ways (point cloud; --mesh by TSDF fusion of the
# multi-view filtered depth maps, the default; --mesh --mesh-raw-depth), each
# measured by cloud-compare: accuracy against reference_cloud.ply (every surface cam0 saw),
# completeness against reference_observed.ply (the surfaces seen within 3 m), aligned through the
# run's trajectory (SE(3) against the exact ground truth). Prints the JSON numbers as a table.
#
#   evaluation/studies/dense/mesh_vs_cloud.sh PKSLAM OUT_DIR [--realism ideal|euroc]
set -euo pipefail
if [ $# -lt 2 ]; then sed -n '2,9p' "$0"; exit 2; fi
pk=$(realpath "$1"); out=$2; realism=ideal
[ "${3:-}" = "--realism" ] && realism=$4
root=$(cd "$(dirname "$0")/../../.." && pwd)
replay="$root/../shared/data/euroc/groundtruth/V1_02_medium.txt"
mkdir -p "$out"
seq="$out/v102_40s_$realism"
[ -d "$seq/mav0" ] || "$pk" simulate --out "$seq" --trajectory "$replay" --start 5 --duration 40 \
  --realism "$realism" --quiet > /dev/null
run="$out/run_$realism"
[ -f "$run/stats.json" ] || "$pk" run --dataset "$seq" --sensor stereo --out "$run" --quiet > /dev/null
gt="$seq/mav0/state_groundtruth_estimate0/data.csv"
[ -f "$seq/truth/state_groundtruth_exact.csv" ] && gt="$seq/truth/state_groundtruth_exact.csv"
/usr/bin/time -v "$pk" dense --run "$run" --dataset "$seq" --out "$out/cloud_$realism.ply" \
  --json "$out/cloud_$realism.json" --quiet > "$out/cloud_$realism.log" 2> "$out/cloud_$realism.time"
/usr/bin/time -v "$pk" dense --run "$run" --dataset "$seq" --mesh "$out/mesh_$realism.ply" \
  --json "$out/mesh_$realism.json" --quiet > "$out/mesh_$realism.log" 2> "$out/mesh_$realism.time"
/usr/bin/time -v "$pk" dense --run "$run" --dataset "$seq" --mesh "$out/meshraw_$realism.ply" \
  --mesh-raw-depth --json "$out/meshraw_$realism.json" --quiet > "$out/meshraw_$realism.log" \
  2> "$out/meshraw_$realism.time"
for kind in cloud mesh meshraw; do
  "$pk" cloud-compare --cloud "$out/${kind}_$realism.ply" --ref "$seq/reference_cloud.ply" \
    --observed-ref "$seq/reference_observed.ply" --align-run "$run" --gt "$gt" \
    --json "$out/compare_${kind}_$realism.json" > "$out/compare_${kind}_$realism.log"
done
/usr/bin/python3 - "$out" "$realism" <<'PY'
import json, re, sys
out, realism = sys.argv[1], sys.argv[2]
print(f"| output ({realism}) | points / triangles | accuracy mean / median (cm) | within 5 cm | "
      "completeness observed 3 m | fusion time (s) | peak memory (MiB) |")
print("|---|---|---|---|---|---|---|")
names = {"cloud": "point cloud", "mesh": "mesh (filtered depth, default)",
         "meshraw": "mesh (raw depth, --mesh-raw-depth)"}
for kind in ["cloud", "mesh", "meshraw"]:
    c = json.load(open(f"{out}/compare_{kind}_{realism}.json"))
    d = json.load(open(f"{out}/{kind}_{realism}.json"))
    t = open(f"{out}/{kind}_{realism}.time").read()
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", t).group(1)
    parts = [float(x) for x in wall.split(":")]
    seconds = parts[-1] + 60 * parts[-2] + (3600 * parts[-3] if len(parts) > 2 else 0)
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", t).group(1)) / 1024
    acc = c["surface_accuracy"] or c["accuracy"]
    obs = c["completeness_observed"][0]
    size = (f"{d['points'] / 1e6:.2f} M points" if kind == "cloud"
            else f"{d['mesh_vertices'] / 1e6:.2f} M vertices, {d['mesh_triangles'] / 1e6:.2f} M triangles")
    print(f"| {names[kind]} | {size} | {100 * acc['mean']:.2f} / {100 * acc['median']:.2f} | "
          f"{100 * acc['within']['0.05']:.1f}% | {100 * obs['completeness']:.1f}% | "
          f"{seconds:.0f} | {rss:.0f} |")
PY
