"""pkslam: keyframe SLAM with a photogrammetric keyframe selector, from Python.

    import pkslam
    slam = pkslam.Slam("settings.yaml", pkslam.VOCABULARY, sensor="stereo")
    for t_ns, left, right in frames:          # uint8 numpy images
        slam.track_stereo(left, right, t_ns)
    slam.shutdown()
    t_ns, poses = slam.body_trajectory()      # int64[N], float64[N, 4, 4] world_from_body
    print(pkslam.evaluate("gt.csv", (t_ns, poses), align="se3")["ate_rmse_m"])
    # camera poses: pkslam.evaluate("gt.csv", slam.camera_trajectory(),
    #                               body_from_camera=slam.body_from_camera)

`simulate()` renders an EuRoC-format sequence with exact ground truth (`pkslam simulate`).
"""
import os
import shutil
import subprocess

from ._pkslam import Slam, evaluate, __version__  # noqa: F401
from . import _paths

VOCABULARY = os.environ.get("PKSLAM_VOCABULARY", _paths.VOCABULARY)


def _executable():
    exe = os.environ.get("PKSLAM_EXECUTABLE") or (
        _paths.EXECUTABLE if os.path.exists(_paths.EXECUTABLE) else shutil.which("pkslam"))
    if not exe:
        raise RuntimeError("pkslam executable not found (set PKSLAM_EXECUTABLE)")
    return exe


def simulate(out, trajectory=None, duration=10.0, seed=1, start=None, motion=None,
             quality=None, realism=None, extra=()):
    """Renders a sequence into `out` (EuRoC layout, settings.yaml, ground truth) and returns
    `out`. trajectory: a TUM/EuRoC ground-truth file to replay (else random motion of the
    `motion` level); the other arguments are `pkslam simulate` options (see its --help)."""
    args = [_executable(), "--log-level", "warn", "simulate", "--out", str(out),
            "--duration", str(duration), "--seed", str(seed), "--quiet"]
    if trajectory is not None:
        args += ["--trajectory", str(trajectory)]
    if start is not None:
        args += ["--start", str(start)]
    if motion is not None:
        args += ["--motion", motion]
    if quality is not None:
        args += ["--quality", quality]
    if realism is not None:
        args += ["--realism", realism]
    args += list(extra)
    result = subprocess.run(args, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"pkslam simulate failed: {result.stderr.strip() or result.stdout.strip()}")
    return str(out)
