#!/bin/bash
# Monocular SLAM from a video file (issue 23): the first 10 s (200 frames) of a simulated V1_01
# replay, encoded as H.264 MP4 with ffmpeg (crf 18), run with `pkslam run --video`, against the
# same 200 frames read as PNGs from the dataset. Prints frames tracked and the Sim3-aligned ATE
# of the camera trajectory of both runs.
#
#   evaluation/studies/video/video_input.sh OUT_DIR [PKSLAM]
set -euo pipefail
if [ $# -lt 1 ]; then sed -n '2,8p' "$0"; exit 2; fi
out=$1
root=$(cd "$(dirname "$0")/../../.." && pwd)
pkslam_bin=${2:-$root/build/bin/pkslam}
pkslam() { "$pkslam_bin" --log-level warn "$@"; }
mkdir -p "$out"
cd "$out"
[ -d v101 ] || pkslam simulate --out v101 --trajectory \
  "$root/../shared/data/euroc/groundtruth/V1_01_easy_original.txt" --start 5 --duration 12 \
  --seed 1 --quiet
rm -rf frames && mkdir frames
i=0
for f in $(ls v101/mav0/cam0/data | head -200); do
  ln -s "../v101/mav0/cam0/data/$f" "frames/$(printf %05d $i).png"
  i=$((i + 1))
done
ffmpeg -y -loglevel error -framerate 20 -i frames/%05d.png -c:v libx264 -pix_fmt yuv420p \
  -crf 18 v101_10s.mp4
pkslam run --video v101_10s.mp4 --settings v101/settings.yaml --sensor mono --quiet --out video \
  > /dev/null
pkslam run --dataset v101 --sensor mono --max-frames 200 --quiet --out png > /dev/null
# The video's clock starts at 0: move it to the dataset's first frame before association.
t0=$(ls v101/mav0/cam0/data | head -1 | sed 's/\.png$//')
awk -v t0="$t0" '/^#/ {print; next} {printf "%.6f", $1 + t0 * 1e-9;
  for (i = 2; i <= NF; i++) printf " %s", $i; printf "\n"}' video/trajectory.txt \
  > video/trajectory_dataset_clock.txt
gt=v101/mav0/state_groundtruth_estimate0/data.csv
for run in png:png/trajectory.txt video:video/trajectory_dataset_clock.txt; do
  name=${run%%:*}; est=${run#*:}
  ate=$(pkslam eval --gt "$gt" --est "$est" --align sim3 --body-from-camera png/body_from_camera.txt \
    | awk '/^ATE \[m\]/ {print $3}')
  tracked=$(/usr/bin/python3 -c "import json; d=json.load(open('$name/stats.json'));
print(f\"{d['frames_in_trajectory']}/{d['frames']}\")")
  echo "$name: tracked $tracked frames, Sim3 ATE $(/usr/bin/python3 -c "print(f'{1e3*$ate:.2f}')") mm"
done
echo "video file: $(stat -c %s v101_10s.mp4) bytes"
