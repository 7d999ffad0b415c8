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

`simulate()` renders an EuRoC-format sequence with exact ground truth (the library behind
`pkslam simulate`).
"""
import os
import shutil

from ._pkslam import Slam, evaluate, _simulate, _SimulateOptions, __version__  # noqa: F401
from . import _paths

VOCABULARY = os.environ.get("PKSLAM_VOCABULARY", _paths.VOCABULARY)


def _executable():
    exe = os.environ.get("PKSLAM_EXECUTABLE") or (
        _paths.EXECUTABLE if os.path.exists(_paths.EXECUTABLE) else shutil.which("pkslam"))
    if not exe:
        raise RuntimeError("pkslam executable not found (set PKSLAM_EXECUTABLE)")
    return exe


def simulate(out, trajectory=None, duration=10.0, seed=1, start=None, motion=None,
             quality=None, realism=None, realism_off=(), realism_params=(), device_seed=1,
             scene=None, camera="euroc", rgbd=False, cloud=True, imu_noise=True):
    """Renders a sequence into `out` (EuRoC layout, settings.yaml, ground truth; TUM RGB-D with
    rgbd=True) and returns `out`, in this process (the library behind `pkslam simulate`: the same
    bytes for the same arguments). trajectory: a TUM/EuRoC ground-truth file to replay (else
    random motion of the `motion` level: easy|medium|difficult). The other arguments are the
    `pkslam simulate` options of the same names (see its --help): quality fast|default|high,
    realism ideal|euroc (None: euroc for replays), realism_off a list of sources,
    realism_params a list of "NAME=VALUE", camera euroc|kitti|vga|tumvi. A bad value raises
    ValueError naming it."""
    options = _SimulateOptions()
    options.out = str(out)
    if trajectory is not None:
        options.trajectory = str(trajectory)
    options.duration_s = float(duration)
    if start is not None:
        options.start_s = float(start)
    options.seed = int(seed)
    options.motion = motion or options.motion
    options.quality = quality or options.quality
    options.realism = realism or ""
    options.realism_off = list(realism_off)
    options.realism_params = list(realism_params)
    options.device_seed = int(device_seed)
    options.scene = scene or ""
    options.camera = camera
    options.rgbd = bool(rgbd)
    options.cloud = bool(cloud)
    options.imu_noise = bool(imu_noise)
    _simulate(options)
    return str(out)
