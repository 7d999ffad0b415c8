#!/usr/bin/python3
"""Opens pages in headless Chromium (Debian `chromium`, software WebGL) and checks what a person
would see.

  check_view.py view PKSLAM WORK      simulate 12 s of V1_02 (or a random flight), run
                                      stereo-inertial with PKS and --trace, `pkslam view`, open it:
                                      the page reports "drawn" without console errors, and the
                                      screenshot has pixels of the trajectory (ATE colours), the
                                      keyframe frustums (rule colours) and the map points.
  check_view.py page VIEW.html [PNG]  open an existing viewer page: the same checks, its size and
                                      time to the first frame, the screenshot kept as PNG.
  check_view.py report REPORT.html    every <img> of a bench report loads (naturalWidth > 0).

Exits 1 with one line per failed check. CTest: viewer.page, viewer.bench_report.
"""

import os
import re
import subprocess
import sys

import cv2
import numpy as np

CHROMIUM = ["chromium", "--headless=new", "--no-sandbox", "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader", "--window-size=1280,800", "--hide-scrollbars"]
HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.abspath(os.path.join(HERE, "..", "..", "..", "shared"))


def chromium(args, url):
    p = subprocess.run(CHROMIUM + args + [url], capture_output=True, text=True, timeout=120)
    return p.stdout, p.stderr


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"failed ({p.returncode}): {' '.join(cmd)}\n{p.stdout[-2000:]}{p.stderr[-2000:]}")
    return p.stdout


def count(img, rgb, tol=12):
    target = np.array(rgb[::-1], dtype=np.int32)  # OpenCV images are BGR
    return int((np.abs(img.astype(np.int32) - target).max(axis=2) <= tol).sum())


def check_view(pkslam, work):
    os.makedirs(work, exist_ok=True)
    seq, out = os.path.join(work, "seq"), os.path.join(work, "run")
    gt = os.path.join(SHARED, "data/euroc/groundtruth/V1_02_medium.txt")
    motion = ["--trajectory", gt, "--start", "5"] if os.path.exists(gt) else ["--motion", "medium"]
    if not os.path.exists(os.path.join(seq, "mav0")):
        run([pkslam, "simulate", "--out", seq, "--duration", "12", "--quality", "fast",
             "--quiet"] + motion)
    run([pkslam, "run", "--dataset", seq, "--sensor", "stereo-inertial", "--selector", "pks",
         "--trace", "--out", out, "--quiet"])
    page = os.path.join(work, "view.html")
    print(run([pkslam, "view", "--run", out, "--dataset", seq, "--out", page]).strip())
    return check_page(page, os.path.join(work, "view.png"))


def check_page(page, shot):
    failures = []
    page = os.path.abspath(page)
    dom, log = chromium(["--dump-dom"], "file://" + page)
    m = re.search(r'<div id="status"([^>]*)>', dom)
    attrs = dict(re.findall(r'data-([\w-]+)="([^"]*)"', m.group(1))) if m else {}
    if attrs.get("state") != "drawn":
        failures.append(f"page state {attrs.get('state')!r}: {attrs.get('errors', '')}")
    print(f"first frame drawn after {attrs.get('first-frame-ms')} ms; "
          f"file {os.path.getsize(page) / 1e6:.1f} MB")
    console = [line for line in log.splitlines() if "CONSOLE" in line and "ERROR" in line]
    if console:
        failures.append("console errors: " + " | ".join(console[:3]))
    shot = os.path.abspath(shot)
    chromium([f"--screenshot={shot}", "--virtual-time-budget=5000"], "file://" + page)
    img = cv2.imread(shot)
    if img is None:
        sys.exit(f"no screenshot at {shot}")
    img = img[:690]  # above the timeline bar
    points = count(img, (40, 40, 200))
    rules = sum(count(img, c) for c in [(214, 39, 40), (44, 160, 44), (255, 127, 14),
                                        (148, 103, 189), (140, 86, 75), (227, 119, 194),
                                        (23, 190, 207), (188, 189, 34), (85, 85, 85)])
    spread = img.max(axis=2).astype(int)
    trajectory = int(((spread >= 222) & (spread <= 236) & (img.min(axis=2) <= 6)).sum())
    print(f"pixels: map points {points}, keyframe frustums {rules}, trajectory {trajectory}")
    for name, n, least in [("map points", points, 200), ("keyframe frustums", rules, 200),
                           ("trajectory", trajectory, 100)]:
        if n < least:
            failures.append(f"{name}: {n} pixels of their colours (< {least})")
    return failures


def check_report(report):
    probe = ("<script>window.addEventListener('load',()=>{const bad=[...document.images]"
             ".filter(i=>!i.complete||i.naturalWidth===0).map(i=>i.getAttribute('src'));"
             "document.body.setAttribute('data-images',document.images.length);"
             "document.body.setAttribute('data-broken',bad.join(' '));});</script>")
    probe_page = report + ".probe.html"
    with open(report) as f, open(probe_page, "w") as g:
        g.write(f.read().replace("</body>", probe + "</body>"))
    dom, _ = chromium(["--dump-dom", "--virtual-time-budget=10000"], "file://" + probe_page)
    os.remove(probe_page)
    images = re.search(r'data-images="(\d+)"', dom)
    broken = re.search(r'data-broken="([^"]*)"', dom)
    if not images:
        return ["the report did not finish loading"]
    print(f"{images.group(1)} images in the report")
    failures = []
    if int(images.group(1)) == 0:
        failures.append("no images in the report")
    if broken and broken.group(1).strip():
        failures.append("broken images: " + broken.group(1))
    return failures


def main():
    if len(sys.argv) >= 2 and sys.argv[1] == "view" and len(sys.argv) == 4:
        failures = check_view(sys.argv[2], sys.argv[3])
    elif len(sys.argv) in (3, 4) and sys.argv[1] == "page":
        failures = check_page(sys.argv[2], sys.argv[3] if len(sys.argv) == 4 else
                              os.path.splitext(sys.argv[2])[0] + ".png")
    elif len(sys.argv) == 3 and sys.argv[1] == "report":
        failures = check_report(sys.argv[2])
    else:
        sys.exit(__doc__)
    for f in failures:
        print("FAILED:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
