#include "core/sensor/rig_calibration.h"

#include <fmt/format.h>

#include <cmath>

#include "core/util/error.h"

namespace pkslam {
namespace {

// Whether a stereo calibration is still the ideal pair a Rectified settings file describes:
// two identical undistorted pinholes, parallel, the right one on the x axis.
bool IsIdealPair(const RigCalibration& c) {
  const CameraModel& a = c.cameras[0];
  const CameraModel& b = c.cameras[1];
  if (a.HasDistortion() || b.HasDistortion()) return false;
  if (a.fx() != b.fx() || a.fy() != b.fy() || a.cx() != b.cx() || a.cy() != b.cy()) return false;
  const Eigen::Vector3d t = c.cam1_from_cam0.translation();
  return c.cam1_from_cam0.so3().Log().norm() == 0.0 && t.y() == 0.0 && t.z() == 0.0 && t.x() < 0;
}

// An ideal pinhole's pixel of a raw pixel of `camera` and back.
Eigen::Vector2d Undistorted(const CameraModel& camera, const Eigen::Vector2d& raw) {
  return camera.HasDistortion() ? camera.UndistortPixel(raw) : raw;
}

std::optional<Eigen::Vector2d> Distorted(const CameraModel& camera, const Eigen::Vector2d& uv) {
  if (!camera.HasDistortion()) return uv;
  const Eigen::Vector3d ray((uv.x() - camera.cx()) / camera.fx(),
                            (uv.y() - camera.cy()) / camera.fy(), 1.0);
  return camera.Project(ray);
}

}  // namespace

void CheckSameRig(const RigCalibration& file, const RigCalibration& estimate) {
  PKSLAM_CHECK_OPTION(file.cameras.size() == estimate.cameras.size(), "calibration",
                      "{} cameras, expected {}", estimate.cameras.size(), file.cameras.size());
  for (std::size_t c = 0; c < file.cameras.size(); ++c) {
    const CameraModel& a = file.cameras[c];
    const CameraModel& b = estimate.cameras[c];
    PKSLAM_CHECK_OPTION(a.width() == b.width() && a.height() == b.height(), "calibration",
                        "cam{} is {}x{}, expected {}x{}", c, b.width(), b.height(), a.width(),
                        a.height());
    PKSLAM_CHECK_OPTION(std::abs(b.fx() / a.fx() - 1) <= 0.03 && std::abs(b.fy() / a.fy() - 1) <= 0.03,
                        "calibration", "cam{} focal length {} / {}, expected {} / {} (within 3%)",
                        c, b.fx(), b.fy(), a.fx(), a.fy());
    PKSLAM_CHECK_OPTION(std::abs(b.cx() - a.cx()) <= 20 && std::abs(b.cy() - a.cy()) <= 20,
                        "calibration", "cam{} principal point ({}, {}), expected ({}, {}) (within "
                        "20 px)",
                        c, b.cx(), b.cy(), a.cx(), a.cy());
  }
  const auto check_extrinsic = [](const char* name, const SE3d& a, const SE3d& b) {
    const SE3d d = a.Inverse() * b;
    PKSLAM_CHECK_OPTION(d.so3().Log().norm() <= 3.0 * M_PI / 180.0 && d.translation().norm() <= 0.03,
                        "calibration", "{} differs by {:.2f} deg and {:.1f} mm (within 3 deg, 30 "
                        "mm)",
                        name, d.so3().Log().norm() * 180.0 / M_PI, d.translation().norm() * 1e3);
  };
  check_extrinsic("body_from_cam0", file.body_from_cam0, estimate.body_from_cam0);
  if (file.stereo()) check_extrinsic("cam1_from_cam0", file.cam1_from_cam0, estimate.cam1_from_cam0);
  PKSLAM_CHECK_OPTION(std::abs(file.time_offset_s - estimate.time_offset_s) <= 0.05, "calibration",
                      "time offset {} s, expected {} s (within 50 ms)", estimate.time_offset_s,
                      file.time_offset_s);
  PKSLAM_CHECK_OPTION((file.gyro_scale - estimate.gyro_scale).cwiseAbs().maxCoeff() <= 0.05,
                      "calibration", "gyro scale error differs by {:.2f}% (within 5%)",
                      100.0 * (file.gyro_scale - estimate.gyro_scale).cwiseAbs().maxCoeff());
  PKSLAM_CHECK_OPTION((file.accel_axes - estimate.accel_axes).cwiseAbs().maxCoeff() <= 0.05,
                      "calibration", "accelerometer axis errors differ by {:.2f}% (within 5%)",
                      100.0 * (file.accel_axes - estimate.accel_axes).cwiseAbs().maxCoeff());
}

RigSetup BuildRig(const RigCalibration& calibration, const RigShape& shape) {
  PKSLAM_CHECK_OPTION(!calibration.cameras.empty(), "calibration", "no camera");
  RigSetup setup;
  auto rig = std::make_shared<CameraRig>();
  rig->sensor = shape.sensor;
  rig->fps = shape.fps;
  rig->pyramid = shape.pyramid;
  rig->imu = shape.imu;
  const SE3d& body_from_cam0 = calibration.body_from_cam0;
  if (IsStereo(shape.sensor)) {
    PKSLAM_CHECK_OPTION(calibration.stereo(), "calibration", "stereo sensor without a cam1");
    if (shape.rectified_input && IsIdealPair(calibration)) {
      rig->camera = calibration.cameras[0];
      rig->baseline = -calibration.cam1_from_cam0.translation().x();
      rig->body_from_camera = body_from_cam0;
    } else {
      setup.rectification.emplace(calibration.cameras[0], calibration.cameras[1],
                                  calibration.cam1_from_cam0);
      rig->camera = setup.rectification->rectified_camera();
      rig->baseline = setup.rectification->baseline();
      rig->body_from_camera = setup.rectification->BodyFromRectLeft(body_from_cam0);
    }
  } else if (calibration.cameras[0].type() == CameraType::kKannalaBrandt8 &&
             !IsRgbd(shape.sensor)) {
    // The view keeps the fisheye's orientation: body_from_camera is the fisheye's.
    setup.undistortion.emplace(calibration.cameras[0]);
    rig->camera = setup.undistortion->pinhole_camera();
    rig->body_from_camera = body_from_cam0;
  } else {
    rig->camera = calibration.cameras[0];
    rig->body_from_camera = body_from_cam0;
    if (IsRgbd(shape.sensor)) {
      rig->depth_factor = shape.depth_factor;
      if (shape.depth_noise_k) rig->depth_noise_k = *shape.depth_noise_k;
      rig->baseline = shape.virtual_baseline;
    }
  }
  if (rig->camera.type() != CameraType::kPinhole) {
    // Tracking, matching and BA work on undistorted keypoints of an ideal pinhole; an RGB-D
    // fisheye's depth image would have to be warped with it.
    throw OptionError(
        "RGB-D needs a pinhole (radial-tangential) camera; a Kannala-Brandt fisheye is tracked "
        "monocular or stereo only");
  }
  rig->UpdateDerived();
  rig->bf = rig->fx * rig->baseline;
  rig->th_depth = shape.th_depth_baselines * rig->baseline;
  setup.rig = std::move(rig);
  return setup;
}

std::optional<Eigen::Vector2d> RawLeftPixel(const RigSetup& setup, const Eigen::Vector2d& uv) {
  if (setup.rectification) return setup.rectification->UnrectifyLeftPixel(uv);
  if (setup.undistortion) return setup.undistortion->DistortPixel(uv);
  return Distorted(setup.rig->camera, uv);
}

std::optional<Eigen::Vector2d> RawRightPixel(const RigSetup& setup, const Eigen::Vector2d& uv) {
  if (setup.rectification) return setup.rectification->UnrectifyRightPixel(uv);
  return uv;
}

std::optional<Eigen::Vector2d> TrackingLeftPixel(const RigSetup& setup,
                                                 const Eigen::Vector2d& raw) {
  if (setup.rectification) return setup.rectification->RectifyLeftPixel(raw);
  if (setup.undistortion) return setup.undistortion->UndistortPixel(raw);
  return Undistorted(setup.rig->camera, raw);
}

std::optional<Eigen::Vector2d> TrackingRightPixel(const RigSetup& setup,
                                                  const Eigen::Vector2d& raw) {
  if (setup.rectification) return setup.rectification->RectifyRightPixel(raw);
  return raw;
}

std::optional<Eigen::Vector2d> RigWarp::Left(const Eigen::Vector2d& uv) const {
  const auto raw = RawLeftPixel(from_, uv);
  if (!raw) return std::nullopt;
  return TrackingLeftPixel(to_, *raw);
}

std::optional<Eigen::Vector2d> RigWarp::Right(const Eigen::Vector2d& uv) const {
  const auto raw = RawRightPixel(from_, uv);
  if (!raw) return std::nullopt;
  return TrackingRightPixel(to_, *raw);
}

namespace {

// d(tracking pixel)/d(raw pixel) at `raw`, by central differences of the mapping (rectification
// or undistortion: smooth, so 1e-3 px steps give ~1e-7 accuracy).
template <typename F>
std::optional<Eigen::Matrix2d> TrackingJacobian(const F& to_tracking, const Eigen::Vector2d& raw) {
  constexpr double kStep = 1e-3;
  Eigen::Matrix2d j;
  for (int c = 0; c < 2; ++c) {
    Eigen::Vector2d d = Eigen::Vector2d::Zero();
    d[c] = kStep;
    const auto plus = to_tracking(raw + d);
    const auto minus = to_tracking(raw - d);
    if (!plus || !minus) return std::nullopt;
    j.col(c) = (*plus - *minus) / (2 * kStep);
  }
  return j;
}

}  // namespace

std::optional<RawMeasurement> MakeRawMeasurement(const RigSetup& setup, const Eigen::Vector2d& uv,
                                                 double u_right, double inv_sigma2,
                                                 const Eigen::Vector2d& raw_keypoint) {
  RawMeasurement m;
  const double sqrt_info = std::sqrt(inv_sigma2);
  if (setup.rectification || setup.undistortion) {
    const auto raw = RawLeftPixel(setup, uv);
    if (!raw) return std::nullopt;
    const auto j = TrackingJacobian(
        [&](const Eigen::Vector2d& p) { return TrackingLeftPixel(setup, p); }, *raw);
    if (!j) return std::nullopt;
    m.left = *raw;
    m.left_whitening = sqrt_info * *j;
  } else {
    m.left = raw_keypoint;
    m.left_whitening = sqrt_info * Eigen::Matrix2d::Identity();
  }
  if (u_right >= 0 && IsStereo(setup.rig->sensor)) {
    const auto raw = RawRightPixel(setup, Eigen::Vector2d(u_right, uv.y()));
    if (!raw) return std::nullopt;
    const auto j = TrackingJacobian(
        [&](const Eigen::Vector2d& p) { return TrackingRightPixel(setup, p); }, *raw);
    if (!j) return std::nullopt;
    m.has_right = true;
    m.right = *raw;
    m.right_whitening = sqrt_info * j->row(0);
  }
  return m;
}

}  // namespace pkslam
