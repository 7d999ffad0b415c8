#!/usr/bin/python3
"""Opens pages in headless Chromium (Debian `chromium`, software WebGL) and checks what a person
would see.

  check_view.py view PKSLAM WORK      simulate 12 s of V1_02 (or a random flight), run
                                      stereo-inertial with PKS and --trace, `pkslam view`, open it:
                                      the page reports "drawn" without console errors, and the
                                      screenshot (legend panel hidden) has pixels of the trajectory
                                      (ATE colours), the keyframe frustums (rule colours) and the
                                      map points. Then a second run (ORB-SLAM3's selector) and its
                                      body trajectory in ORB-SLAM3's f_*.txt format on one page
                                      with the first: the file's ATE equals the second run's (the
                                      body poses are moved into the camera), and from the page
                                      (window.pkslamView and the DOM): 3 trajectory rows with
                                      checkboxes, unchecking one hides that trajectory only, the
                                      axes, grid and scale bar exist, the scale bar reads a length
                                      in metres that grows when the camera backs off, every
                                      keyframe rule is explained, and the strip has time tick
                                      labels, y labels and a legend of its series.
  check_view.py page VIEW.html [PNG]  open an existing viewer page: the same checks, its size and
                                      time to the first frame, the screenshot kept as PNG.
  check_view.py report REPORT.html    every <img> of a bench report loads (naturalWidth > 0).

Exits 1 with one line per failed check. CTest: viewer.page, viewer.bench_report.
"""

import html
import json
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
    failures = check_page(page, os.path.join(work, "view.png"))
    return failures + check_several(pkslam, work, seq, out)


def orbslam3_format(tum_file, out_file):
    """A TUM trajectory rewritten as ORB-SLAM3's f_*.txt (nanosecond stamps, TUM columns)."""
    with open(tum_file) as f, open(out_file, "w") as g:
        for line in f:
            if line.startswith("#") or not line.strip():
                continue
            stamp, rest = line.split(None, 1)
            seconds, _, fraction = stamp.partition(".")
            g.write(f"{int(seconds) * 10**9 + int(fraction.ljust(9, '0')[:9])}.000000 {rest}")


# Runs inside the page after viewer.js; leaves its findings as JSON in <body data-probe>.
PROBE = """<script>(function () {
  const out = {};
  try {
    const v = window.pkslamView;
    const rows = [...document.querySelectorAll('#panel .track-row')];
    out.rows = rows.length;
    out.rowsWithCheckbox = rows.filter((r) => r.querySelector('input[type=checkbox]')).length;
    out.labels = v.tracks.map((t) => t.label);
    out.before = v.tracks.map((t) => t.object.visible);
    const box = rows[1].querySelector('input[data-layer]');
    box.checked = false;
    box.dispatchEvent(new Event('change'));
    out.after = v.tracks.map((t) => t.object.visible);
    box.checked = true;
    box.dispatchEvent(new Event('change'));
    out.again = v.tracks[1].object.visible;
    out.axes = v.axes ? v.axes.children.length : 0;
    out.axesVisible = !!(v.axes && v.axes.visible);
    out.grid = !!(v.grid && v.grid.visible && v.grid.geometry.attributes.position.count > 4);
    out.gridCell = v.gridCell;
    out.gridText = document.querySelector('#panel input[data-layer="grid"]').parentElement
      .parentElement.textContent;
    const gridBox = document.querySelector('#panel input[data-layer="grid"]');
    gridBox.checked = false;
    gridBox.dispatchEvent(new Event('change'));
    out.gridHidden = !v.grid.visible;
    out.scaleText = document.getElementById('scalebar-text').textContent;
    out.scaleWidth = document.getElementById('scalebar-bar').getBoundingClientRect().width;
    out.scaleBefore = v.scaleBar.metres();
    const t = v.controls.target;
    v.camera.position.sub(t).multiplyScalar(4).add(t);
    v.controls.update();
    v.draw();
    out.scaleAfter = v.scaleBar.metres();
    out.rules = [...document.querySelectorAll('#legend .rule b')].map((b) => b.textContent);
    out.glossed = [...document.querySelectorAll('#panel details .gloss b')]
      .map((b) => b.textContent);
    out.rampTicks = document.querySelector('#panel .ramp-ticks').textContent;
    const strip = v.strip();
    out.ticks = strip.ticks;
    out.yLabels = strip.yLabels;
    out.legend = strip.legend;
    out.stripLegend = document.getElementById('striplegend').textContent;
  } catch (e) {
    out.error = String(e.stack || e);
  }
  document.body.setAttribute('data-probe', JSON.stringify(out));
})();</script>"""


def probe(page):
    """Runs PROBE in a copy of the page; returns (its findings, the status attributes, console
    errors)."""
    probe_page = page + ".probe.html"
    with open(page) as f, open(probe_page, "w") as g:
        before, tag, after = f.read().rpartition("</body>")  # the page's own, not a script's
        g.write(before + PROBE + tag + after)
    dom, log = chromium(["--dump-dom"], "file://" + os.path.abspath(probe_page))
    os.remove(probe_page)
    m = re.search(r'data-probe="([^"]*)"', dom)
    found = json.loads(html.unescape(m.group(1))) if m else {"error": "the probe did not run"}
    m = re.search(r'<div id="status"([^>]*)>', dom)
    status = dict(re.findall(r'data-([\w-]+)="([^"]*)"', m.group(1))) if m else {}
    console = [line for line in log.splitlines() if "CONSOLE" in line and "ERROR" in line]
    return found, status, console


def check_several(pkslam, work, seq, first):
    """Two runs and a bare trajectory on one page."""
    second = os.path.join(work, "run_orbslam3")
    run([pkslam, "run", "--dataset", seq, "--sensor", "stereo-inertial", "--selector",
         "orbslam3", "--trace", "--out", second, "--quiet"])
    bare = os.path.join(work, "f_run_orbslam3.txt")
    orbslam3_format(os.path.join(second, "trajectory_body.txt"), bare)
    page = os.path.join(work, "view_several.html")
    text = run([pkslam, "view", "--run", first, "--run", second, "--trajectory", bare,
                "--label", "ORB-SLAM3 format", "--dataset", seq, "--out", page]).strip()
    print(text)
    failures = []
    ates = dict(re.findall(r"^  \+ (.+?) \((?:run|trajectory)\): .*ATE ([0-9.]+) m", text, re.M))
    if ates.get("ORB-SLAM3 format") is None or ates.get("ORB-SLAM3 format") != ates.get(
            "run_orbslam3"):
        failures.append(f"the body file's ATE is not the second run's camera ATE: {ates}")
    found, status, console = probe(page)
    print("page:", json.dumps(found)[:1500])
    if status.get("state") != "drawn":
        failures.append(f"several: page state {status.get('state')!r}: {status.get('errors', '')}")
    if console:
        failures.append("several: console errors: " + " | ".join(console[:3]))
    if "error" in found:
        return failures + ["several: probe failed: " + found["error"]]
    expect = [
        ("3 trajectory rows with checkboxes", found["rows"] == 3 and found["rowsWithCheckbox"] == 3),
        ("labels", found["labels"] == ["run", "run_orbslam3", "ORB-SLAM3 format"]),
        ("unchecking row 2 hides trajectory 2 only",
         found["before"] == [True, True, True] and found["after"] == [True, False, True]
         and found["again"]),
        ("axes: 3 labels and the lines", found["axes"] == 4 and found["axesVisible"]),
        ("grid drawn, its cell stated, toggled off",
         found["grid"] and found["gridCell"] > 0 and " m cells" in found["gridText"]
         and found["gridHidden"]),
        ("scale bar reads a length in metres",
         re.fullmatch(r"[0-9.]+ m", found["scaleText"]) is not None
         and 60 <= found["scaleWidth"] <= 151),
        ("scale bar grows as the camera backs off", found["scaleAfter"] > found["scaleBefore"]),
        ("every rule name explained",
         len(found["rules"]) > 0 and all(part in found["glossed"] for rule in found["rules"]
                                         for part in re.split(r"[+;]", rule))),
        ("ATE ramp numbers in metres", re.search(r"0.*≥ [0-9.]+ m", found["rampTicks"]) is not None),
        ("strip time ticks in seconds",
         len(found["ticks"]) >= 3 and all(re.fullmatch(r"[0-9.]+ s", t) for t in found["ticks"])),
        ("strip y labels", any(y.startswith("tracked:") for y in found["yLabels"])
         and any(y.startswith("D_c:") for y in found["yLabels"])),
        ("strip legend names the series",
         all(name in found["stripLegend"] for name in
             ["tracked points", "keyframes", "D_c", "Th_adaptive", "current frame"])),
    ]
    for name, ok in expect:
        if not ok:
            failures.append("several: " + name)
    return failures


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
    # The screenshot is of the 3-D view: the legend panel (whose swatches have the colours
    # counted below) is hidden in a copy of the page.
    shot = os.path.abspath(shot)
    bare = page + ".nopanel.html"
    with open(page) as f, open(bare, "w") as g:
        g.write(f.read().replace("</head>", "<style>#panel { visibility: hidden; }</style></head>", 1))
    chromium([f"--screenshot={shot}", "--virtual-time-budget=5000"], "file://" + bare)
    os.remove(bare)
    img = cv2.imread(shot)
    if img is None:
        sys.exit(f"no screenshot at {shot}")
    img = img[:650]  # above the timeline bar (150 px of the 800)
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
