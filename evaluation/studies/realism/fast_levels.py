#!/usr/bin/python3
"""FAST corners at ORB-SLAM3's two thresholds (20, and 7 where 20 finds nothing) per folder of
frames, with the share of 32x32 cells holding no corner at each, the mean Sobel gradient and the
saturated share: image_stats.py's measures plus the weak texture an ORB front end falls back on.

  /usr/bin/python3 evaluation/studies/realism/fast_levels.py ../shared/data/euroc/V1_01_easy_static SEQ [SEQ...]

A folder is a folder of PNGs or an EuRoC sequence (mav0/cam0/data); about 60 frames per folder
are measured, evenly spaced.
"""
import argparse
import glob
import os

import cv2
import numpy as np


def frames(path, count):
    if os.path.isdir(os.path.join(path, 'mav0', 'cam0', 'data')):
        path = os.path.join(path, 'mav0', 'cam0', 'data')
    files = sorted(glob.glob(os.path.join(path, '*.png')))
    if not files:
        raise SystemExit(f'fast_levels: no PNG files in {path}')
    return files[::max(1, len(files) // count)]


def measure(files):
    rows = []
    for f in files:
        im = cv2.imread(f, cv2.IMREAD_GRAYSCALE)
        if im is None:
            raise SystemExit(f'fast_levels: cannot read {f}')
        row = []
        for threshold in (7, 20):
            corners = cv2.FastFeatureDetector_create(threshold=threshold).detect(im)
            rows_c, cols_c = im.shape[0] // 32, im.shape[1] // 32
            occupied = np.zeros((rows_c, cols_c), bool)
            for k in corners:
                y, x = int(k.pt[1]) // 32, int(k.pt[0]) // 32
                if y < rows_c and x < cols_c:
                    occupied[y, x] = True
            row += [len(corners), 100 * (1 - occupied.mean())]
        gradient = np.hypot(cv2.Sobel(im, cv2.CV_32F, 1, 0), cv2.Sobel(im, cv2.CV_32F, 0, 1))
        row += [gradient.mean(), 100 * (im >= 250).mean()]
        rows.append(row)
    a = np.array(rows)
    return [np.median(a[:, 0]), a[:, 1].mean(), np.median(a[:, 2]), a[:, 3].mean(),
            a[:, 4].mean(), a[:, 5].mean()]


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('folders', nargs='+')
    ap.add_argument('--frames', type=int, default=60, help='frames measured per folder')
    args = ap.parse_args()
    print(f"{'folder':40s} {'FAST-7':>8s} {'empty7%':>8s} {'FAST-20':>8s} {'empty20%':>9s} "
          f"{'gradient':>9s} {'sat%':>6s}")
    for folder in args.folders:
        m = measure(frames(folder, args.frames))
        print(f'{folder[-40:]:40s} {m[0]:8.0f} {m[1]:8.1f} {m[2]:8.0f} {m[3]:9.1f} {m[4]:9.1f} '
              f'{m[5]:6.1f}')


if __name__ == '__main__':
    main()
