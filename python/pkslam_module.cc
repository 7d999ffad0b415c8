// The Python module `pkslam` (its native part, pkslam._pkslam): the public C++ API
// (api/include/pkslam/pkslam.h) with NumPy arrays in and out. Images are uint8 (H, W) or
// (H, W, 3) arrays, depth uint16 or float32 (H, W), poses 4x4 float64; camera_trajectory()
// holds world_from_camera, body_trajectory() world_from_body. Bad arguments raise ValueError
// naming the argument (std::invalid_argument in the C++ API).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <map>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "pkslam/pkslam.h"

namespace py = pybind11;
namespace api = pkslam::api;

namespace {

// A cv::Mat view of a C-contiguous array (no copy; valid while the array lives).
cv::Mat View(const py::array& a, const char* what) {
  const py::buffer_info b = a.request();
  if (b.ndim != 2 && !(b.ndim == 3 && (b.shape[2] == 3 || b.shape[2] == 1))) {
    throw std::invalid_argument(std::string(what) + ": expected an (H, W) or (H, W, 3) array");
  }
  if (!(a.flags() & py::array::c_style)) {
    throw std::invalid_argument(std::string(what) + ": array must be C-contiguous");
  }
  int depth = 0;
  if (b.format == py::format_descriptor<std::uint8_t>::format()) {
    depth = CV_8U;
  } else if (b.format == py::format_descriptor<std::uint16_t>::format()) {
    depth = CV_16U;
  } else if (b.format == py::format_descriptor<float>::format()) {
    depth = CV_32F;
  } else {
    throw std::invalid_argument(std::string(what) + ": dtype must be uint8, uint16 or float32");
  }
  const int channels = b.ndim == 3 ? static_cast<int>(b.shape[2]) : 1;
  return cv::Mat(static_cast<int>(b.shape[0]), static_cast<int>(b.shape[1]),
                 CV_MAKETYPE(depth, channels), b.ptr);
}

template <typename Pose>
const Eigen::Matrix4d& PoseMatrix(const Pose& p) {
  if constexpr (std::is_same_v<Pose, api::StampedPose>) {
    return p.world_from_camera;
  } else {
    return p.world_from_body;
  }
}

template <typename Pose>
py::tuple TrajectoryArrays(const std::vector<Pose>& poses) {
  py::array_t<std::int64_t> t(static_cast<py::ssize_t>(poses.size()));
  py::array_t<double> m({static_cast<py::ssize_t>(poses.size()), py::ssize_t{4}, py::ssize_t{4}});
  auto tv = t.mutable_unchecked<1>();
  auto mv = m.mutable_unchecked<3>();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    tv(static_cast<py::ssize_t>(i)) = poses[i].t_ns;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c)
        mv(static_cast<py::ssize_t>(i), r, c) = PoseMatrix(poses[i])(r, c);
    }
  }
  return py::make_tuple(t, m);
}

std::vector<api::StampedPose> PosesFromArrays(const py::array_t<std::int64_t>& t,
                                              const py::array_t<double>& m) {
  if (m.ndim() != 3 || m.shape(1) != 4 || m.shape(2) != 4 || t.ndim() != 1 ||
      t.shape(0) != m.shape(0)) {
    throw std::invalid_argument("est: expected (t_ns[N], poses[N, 4, 4])");
  }
  auto tv = t.unchecked<1>();
  auto mv = m.unchecked<3>();
  std::vector<api::StampedPose> out(static_cast<std::size_t>(t.shape(0)));
  for (py::ssize_t i = 0; i < t.shape(0); ++i) {
    out[static_cast<std::size_t>(i)].t_ns = tv(i);
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c)
        out[static_cast<std::size_t>(i)].world_from_camera(r, c) = mv(i, r, c);
    }
  }
  return out;
}

py::dict EvaluationDict(const api::Evaluation& e) {
  py::dict d;
  d["pairs"] = e.pairs;
  d["scale"] = e.scale;
  d["ate_rmse_m"] = e.ate_rmse_m;
  d["ate_mean_m"] = e.ate_mean_m;
  d["ate_median_m"] = e.ate_median_m;
  d["ate_max_m"] = e.ate_max_m;
  d["ate_rot_rmse_deg"] = e.ate_rot_rmse_deg;
  d["rpe_trans_rmse_m"] = e.rpe_trans_rmse_m;
  d["rpe_rot_rmse_deg"] = e.rpe_rot_rmse_deg;
  return d;
}

// Slam: construction, the images and IMU samples it tracks, its state and pose.
void BindSlamTracking(py::class_<api::Slam>* slam) {
  py::class_<api::Slam>& c = *slam;
  c.def(py::init([](const std::string& settings, const std::string& vocabulary,
                    const std::string& sensor, const std::string& selector, bool deterministic,
                    bool localise_only, bool loop_closing,
                    const std::map<std::string, double>& selector_parameters) {
          api::SlamOptions o;
          o.settings = settings;
          o.vocabulary = vocabulary;
          o.sensor = sensor;
          o.selector = selector;
          o.deterministic = deterministic;
          o.localise_only = localise_only;
          o.loop_closing = loop_closing;
          o.selector_parameters = selector_parameters;
          return std::make_unique<api::Slam>(o);
        }),
        py::arg("settings"), py::arg("vocabulary"), py::arg("sensor") = "stereo",
        py::arg("selector") = "orbslam3", py::arg("deterministic") = false,
        py::arg("localise_only") = false, py::arg("loop_closing") = true,
        py::arg("selector_parameters") = std::map<std::string, double>{})
      .def(
          "track_mono",
          [](api::Slam& s, const py::array& image, std::int64_t t_ns) {
            return api::SlamStateName(s.TrackMonocular(View(image, "image"), t_ns));
          },
          py::arg("image"), py::arg("t_ns"), "Track one image; returns the tracking state")
      .def(
          "track_stereo",
          [](api::Slam& s, const py::array& left, const py::array& right, std::int64_t t_ns) {
            return api::SlamStateName(
                s.TrackStereo(View(left, "left"), View(right, "right"), t_ns));
          },
          py::arg("left"), py::arg("right"), py::arg("t_ns"))
      .def(
          "track_rgbd",
          [](api::Slam& s, const py::array& image, const py::array& depth, std::int64_t t_ns) {
            return api::SlamStateName(
                s.TrackRgbd(View(image, "image"), View(depth, "depth"), t_ns));
          },
          py::arg("image"), py::arg("depth"), py::arg("t_ns"))
      .def(
          "add_imu",
          [](api::Slam& s, const py::array_t<std::int64_t>& t_ns, const py::array_t<double>& gyro,
             const py::array_t<double>& accel) {
            if (gyro.ndim() != 2 || gyro.shape(1) != 3 || accel.ndim() != 2 ||
                accel.shape(1) != 3 || t_ns.ndim() != 1 || gyro.shape(0) != t_ns.shape(0) ||
                accel.shape(0) != t_ns.shape(0)) {
              throw std::invalid_argument("add_imu: expected t_ns[N], gyro[N, 3], accel[N, 3]");
            }
            auto t = t_ns.unchecked<1>();
            auto g = gyro.unchecked<2>();
            auto a = accel.unchecked<2>();
            std::vector<api::ImuSample> samples(static_cast<std::size_t>(t_ns.shape(0)));
            for (py::ssize_t i = 0; i < t_ns.shape(0); ++i) {
              auto& x = samples[static_cast<std::size_t>(i)];
              x.t_ns = t(i);
              x.gyro = {g(i, 0), g(i, 1), g(i, 2)};
              x.accel = {a(i, 0), a(i, 1), a(i, 2)};
            }
            s.AddImu(samples);
          },
          py::arg("t_ns"), py::arg("gyro"), py::arg("accel"))
      .def_property_readonly("state",
                             [](const api::Slam& s) { return api::SlamStateName(s.state()); })
      .def("pose", &api::Slam::CurrentPose,
           "world_from_camera (4x4) of the last frame, or None when it was not tracked");
}

// Slam: the map (points, keyframes, the last frame's inliers), its modes and map files.
void BindSlamMap(py::class_<api::Slam>* slam) {
  py::class_<api::Slam>& c = *slam;
  c.def(
       "map_points",
       [](const api::Slam& s) {
         const auto points = s.MapPoints();
         const auto n = static_cast<py::ssize_t>(points.size());
         py::array_t<double> xyz({n, py::ssize_t{3}});
         py::array_t<std::int64_t> ids(n);
         py::array_t<std::int32_t> observations(n);
         auto x = xyz.mutable_unchecked<2>();
         auto id = ids.mutable_unchecked<1>();
         auto obs = observations.mutable_unchecked<1>();
         for (py::ssize_t i = 0; i < n; ++i) {
           const auto& p = points[static_cast<std::size_t>(i)];
           for (int c = 0; c < 3; ++c) x(i, c) = p.world_position(c);
           id(i) = p.id;
           obs(i) = p.observations;
         }
         return py::make_tuple(xyz, ids, observations);
       },
       "(world positions[N, 3], ids[N], observing keyframes[N]) of the largest map's points")
      .def(
          "keyframes",
          [](const api::Slam& s) {
            const auto keyframes = s.KeyFrames();
            std::vector<api::StampedPose> poses;
            py::array_t<std::int64_t> ids(static_cast<py::ssize_t>(keyframes.size()));
            auto id = ids.mutable_unchecked<1>();
            for (std::size_t i = 0; i < keyframes.size(); ++i) {
              poses.push_back({keyframes[i].t_ns, keyframes[i].world_from_camera});
              id(static_cast<py::ssize_t>(i)) = keyframes[i].id;
            }
            const py::tuple trajectory = TrajectoryArrays(poses);
            return py::make_tuple(trajectory[0], trajectory[1], ids);
          },
          "(t_ns[N], world_from_camera[N, 4, 4], ids[N]) of the largest map's keyframes")
      .def(
          "tracked_keypoints",
          [](const api::Slam& s) {
            const auto keypoints = s.TrackedKeypoints();
            const auto n = static_cast<py::ssize_t>(keypoints.size());
            py::array_t<float> uv({n, py::ssize_t{2}});
            py::array_t<std::int64_t> ids(n);
            auto x = uv.mutable_unchecked<2>();
            auto id = ids.mutable_unchecked<1>();
            for (py::ssize_t i = 0; i < n; ++i) {
              const auto& k = keypoints[static_cast<std::size_t>(i)];
              x(i, 0) = k.u;
              x(i, 1) = k.v;
              id(i) = k.map_point_id;
            }
            return py::make_tuple(uv, ids);
          },
          "(undistorted pixels[N, 2], map point ids[N]) of the last frame's pose inliers "
          "(empty when it was not tracked)")
      .def_property(
          "localisation_mode", &api::Slam::LocalisationMode, &api::Slam::SetLocalisationMode,
          "Localisation mode: True tracks against the current map without new keyframes (ORB-"
          "SLAM3's ActivateLocalizationMode); False resumes mapping")
      .def("reset", &api::Slam::Reset, py::call_guard<py::gil_scoped_release>(),
           "Forget every map and start again with the same options (ORB-SLAM3's Reset)")
      .def_property_readonly("selector", &api::Slam::Selector)
      .def_property_readonly("selector_parameters", &api::Slam::SelectorParameters,
                             "The parameters given to the selector (settings' Keyframe.* and "
                             "selector_parameters); others are at its defaults")
      .def_property_readonly("num_keyframes", &api::Slam::NumKeyFrames)
      .def_property_readonly("num_map_points", &api::Slam::NumMapPoints)
      .def("save_map", &api::Slam::SaveMap, py::arg("file"))
      .def("load_map", &api::Slam::LoadMap, py::arg("file"))
      .def("shutdown", &api::Slam::Shutdown, py::call_guard<py::gil_scoped_release>());
}

// Slam: the trajectories of every tracked frame and of the keyframes.
void BindSlamTrajectories(py::class_<api::Slam>* slam) {
  py::class_<api::Slam>& c = *slam;
  c.def(
       "camera_trajectory",
       [](const api::Slam& s) { return TrajectoryArrays(s.CameraTrajectory()); },
       "(t_ns[N], world_from_camera[N, 4, 4]) of every tracked frame (the left camera)")
      .def(
          "body_trajectory",
          [](const api::Slam& s) { return TrajectoryArrays(s.BodyTrajectory()); },
          "(t_ns[N], world_from_body[N, 4, 4]) of every tracked frame: the body (IMU) frame "
          "that EuRoC ground truth describes (not for visual monocular maps)")
      .def(
          "trajectory",
          [](const api::Slam&) -> py::tuple {
            throw std::invalid_argument(
                "Slam.trajectory() is ambiguous: use camera_trajectory() (world_from_camera) or "
                "body_trajectory() (world_from_body, what EuRoC ground truth describes)");
          },
          "Removed: camera_trajectory() or body_trajectory()")
      .def_property_readonly("body_from_camera", &api::Slam::BodyFromCamera,
                             "The rig's camera-to-body transform (4x4)")
      .def(
          "keyframe_trajectory",
          [](const api::Slam& s) { return TrajectoryArrays(s.KeyFrameTrajectory()); },
          "(t_ns[N], world_from_camera[N, 4, 4]) of the keyframes");
}

// pkslam.evaluate(): ATE/RPE as `pkslam eval`.
void BindEvaluate(py::module_& m) {
  m.def(
      "evaluate",
      [](const std::string& gt, const py::object& est, const std::string& align,
         const std::optional<Eigen::Matrix4d>& body_from_camera) {
        if (py::isinstance<py::str>(est)) {
          return EvaluationDict(api::Evaluate(gt, est.cast<std::string>(), align, body_from_camera));
        }
        if (!py::isinstance<py::tuple>(est) || py::len(est) != 2) {
          throw std::invalid_argument("est: a trajectory file or (t_ns, poses) arrays");
        }
        const auto pair = est.cast<py::tuple>();
        return EvaluationDict(
            api::Evaluate(gt,
                          PosesFromArrays(pair[0].cast<py::array_t<std::int64_t>>(),
                                          pair[1].cast<py::array_t<double>>()),
                          align, body_from_camera));
      },
      py::arg("gt"), py::arg("est"), py::arg("align") = "se3",
      py::arg("body_from_camera") = py::none(),
      "ATE/RPE of an estimate against a ground-truth file, as `pkslam eval`. est: a trajectory "
      "file or (t_ns, poses) arrays in the ground truth's frame (Slam.body_trajectory() against "
      "EuRoC's body ground truth); camera poses (Slam.camera_trajectory()) with "
      "body_from_camera=Slam.body_from_camera, which moves the truth into the camera. A camera "
      "trajectory against body truth without it raises RuntimeError with that hint.");
}

void BindSimulate(py::module_& m) {
  // api::SimulateOptions field by field; pkslam.simulate() (pkslam/__init__.py) fills it.
  py::class_<api::SimulateOptions>(m, "_SimulateOptions")
      .def(py::init<>())
      .def_readwrite("out", &api::SimulateOptions::out)
      .def_readwrite("trajectory", &api::SimulateOptions::trajectory)
      .def_readwrite("duration_s", &api::SimulateOptions::duration_s)
      .def_readwrite("start_s", &api::SimulateOptions::start_s)
      .def_readwrite("seed", &api::SimulateOptions::seed)
      .def_readwrite("motion", &api::SimulateOptions::motion)
      .def_readwrite("quality", &api::SimulateOptions::quality)
      .def_readwrite("realism", &api::SimulateOptions::realism)
      .def_readwrite("realism_off", &api::SimulateOptions::realism_off)
      .def_readwrite("realism_params", &api::SimulateOptions::realism_params)
      .def_readwrite("device_seed", &api::SimulateOptions::device_seed)
      .def_readwrite("scene", &api::SimulateOptions::scene)
      .def_readwrite("camera", &api::SimulateOptions::camera)
      .def_readwrite("rgbd", &api::SimulateOptions::rgbd)
      .def_readwrite("cloud", &api::SimulateOptions::cloud)
      .def_readwrite("imu_noise", &api::SimulateOptions::imu_noise);
  // Rendering takes seconds to minutes: other Python threads run meanwhile.
  m.def(
      "_simulate", [](const api::SimulateOptions& o) { api::Simulate(o); },
      py::call_guard<py::gil_scoped_release>(), "api::Simulate");
}

}  // namespace

PYBIND11_MODULE(_pkslam, m) {
  m.doc() = "pkslam: keyframe SLAM (the C++ library's public API with NumPy arrays)";
  m.attr("__version__") = api::kApiVersion;
  py::class_<api::Slam> slam(m, "Slam");
  BindSlamTracking(&slam);
  BindSlamMap(&slam);
  BindSlamTrajectories(&slam);
  BindEvaluate(m);
  BindSimulate(m);
}
