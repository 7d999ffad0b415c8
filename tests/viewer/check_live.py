#!/usr/bin/python3
"""The live view of a running `pkslam run --live-view` in headless Chromium (CTest viewer.live).

  check_live.py PKSLAM WORK

Simulates a 40 s random flight, runs stereo SLAM on it at real-time pace with --live-view on a
free port, and while it runs (headless Chromium with a software GPU takes 7-10 s per opening on
a 2-core machine, so the flight outlasts both openings and the wait between them):
  - data.json answers, and its pose count grows between two requests 4 s apart;
  - frame.jpg is a JPEG of the camera's size, and the frame's tracked keypoints are sent;
  - the page, opened twice in headless Chromium 4 s apart, reports "drawn" without script errors
    and the number of poses it has drawn grows from the first opening to the second;
  - the run ends with exit 0 and its usual outputs.
Exits 1 with one line per failed check.
"""

import json
import os
import re
import socket
import subprocess
import sys
import time
import urllib.request

CHROMIUM = ["chromium", "--headless=new", "--no-sandbox", "--use-angle=swiftshader",
            "--enable-unsafe-swiftshader", "--window-size=1280,800", "--hide-scrollbars"]


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def get(url, timeout=5):
    with urllib.request.urlopen(url, timeout=timeout) as r:
        return r.read()


def page_status(url):
    """The #status element's attributes after the page has polled for a while (virtual time)."""
    p = subprocess.run(CHROMIUM + ["--virtual-time-budget=2500", "--dump-dom", url],
                       capture_output=True, text=True, timeout=120)
    m = re.search(r'<div id="status"([^>]*)>', p.stdout)
    return dict(re.findall(r'data-([a-z-]+)="([^"]*)"', m.group(1))) if m else {}


def main():
    pkslam, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    seq = os.path.join(work, "seq")
    subprocess.run([pkslam, "--log-level", "warn", "simulate", "--out", seq, "--motion", "medium",
                    "--duration", "40", "--quality", "fast", "--quiet", "--no-cloud", "--seed",
                    "3"], check=True, capture_output=True)
    port = free_port()
    base = f"http://127.0.0.1:{port}/"
    run = subprocess.Popen([pkslam, "--log-level", "warn", "run", "--dataset", seq, "--out",
                            os.path.join(work, "run"), "--realtime", "--quiet", "--live-view",
                            str(port)], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           text=True)
    failures = []
    try:
        data = None
        for _ in range(100):  # the server answers once the dataset is read
            try:
                data = json.loads(get(base + "data.json"))
                if data["pose_count"] > 0:
                    break
            except OSError:
                pass
            time.sleep(0.1)
        if data is None:
            sys.exit("live view: no answer from " + base + "data.json")
        first = page_status(base)
        poses_a = json.loads(get(base + "data.json"))["pose_count"]
        time.sleep(4)
        later = json.loads(get(base + "data.json?since=%d" % poses_a))
        jpeg = get(base + "frame.jpg")
        second = page_status(base)
        if later["pose_count"] <= poses_a:
            failures.append(f"data.json: {poses_a} poses, then {later['pose_count']} 4 s later")
        if len(later["poses"]) != 3 * (later["pose_count"] - poses_a):
            failures.append("data.json?since=N: not the poses after the N-th")
        if not jpeg.startswith(b"\xff\xd8") or len(jpeg) < 5000:
            failures.append(f"frame.jpg: not a JPEG image ({len(jpeg)} bytes)")
        if len(later["keypoints"]) < 2 * 30:
            failures.append(f"data.json: {len(later['keypoints']) // 2} tracked keypoints sent")
        if len(later["points"]) < 3 * 100 or len(later["keyframes"]) < 7 * 2:
            failures.append("data.json: the map (points, keyframes) is missing")
        for name, status in (("first", first), ("second", second)):
            if status.get("state") not in ("drawn", "finished") or status.get("errors"):
                failures.append(f"page, {name} opening: state {status.get('state')!r}, "
                                f"errors {status.get('errors')!r}")
        a, b = int(first.get("poses", 0)), int(second.get("poses", 0))
        if not 0 < a < b:
            failures.append(f"page: poses drawn {a} at the first opening, {b} 4 s later")
        print(f"live view: data.json {poses_a} -> {later['pose_count']} poses; page drew {a} -> "
              f"{b} poses; {len(later['keypoints']) // 2} keypoints, "
              f"{len(later['points']) // 3} map points, frame.jpg {len(jpeg)} bytes")
    finally:
        out, _ = run.communicate(timeout=120)
    if run.returncode != 0:
        failures.append(f"run exit {run.returncode}: {out[-500:]}")
    if not os.path.exists(os.path.join(work, "run", "trajectory.txt")):
        failures.append("run: no trajectory.txt")
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
