// Settings: validation and the ORB-SLAM3 v1.0 settings reader (the writer is in
// settings_writer.cc).
#include "io/settings.h"

#include <fmt/format.h>

#include <cmath>
#include <optional>

#include "core/util/error.h"
#include "io/opencv_yaml.h"
#include "io/settings_keys.h"
#include "io/settings_legacy.h"

namespace pkslam {

namespace {

void CheckRigid(const SE3d& transform, const std::string& name) {
  PKSLAM_CHECK_OPTION(
      transform.translation().allFinite() && transform.quaternion().coeffs().allFinite(), name,
      "non-finite transform");
}

}  // namespace

bool SameCalibration(const CameraModel& a, const CameraModel& b) {
  return a.type() == b.type() && a.width() == b.width() && a.height() == b.height() &&
         a.fx() == b.fx() && a.fy() == b.fy() && a.cx() == b.cx() && a.cy() == b.cy() &&
         a.distortion() == b.distortion();
}

double Settings::BaselineM() const {
  if (stereo_baseline_m) return *stereo_baseline_m;
  if (right_from_left) return right_from_left->translation().norm();
  return 0.0;
}

double Settings::Bf() const { return BaselineM() * camera1.fx(); }

void Settings::Check() const {
  // CameraModel's factories validate intrinsics; a default-constructed model is not set.
  PKSLAM_CHECK_OPTION(camera1.width() > 0 && camera1.fx() > 0, "camera1", "not set");
  if (camera2) {
    PKSLAM_CHECK_OPTION(camera2->width() > 0 && camera2->fx() > 0, "camera2", "not set");
    PKSLAM_CHECK_OPTION(camera2->type() == camera1.type(), "camera2.type", "differs from camera1");
    PKSLAM_CHECK_OPTION(
        camera2->width() == camera1.width() && camera2->height() == camera1.height(),
        "camera2 size", "{}x{} differs from camera1's {}x{}", camera2->width(), camera2->height(),
        camera1.width(), camera1.height());
    PKSLAM_CHECK_OPTION(right_from_left.has_value(), "right_from_left", "required with camera2");
  }
  PKSLAM_CHECK_OPTION(fps > 0 && std::isfinite(fps), "fps", "{}", fps);
  if (rectified_stereo) {
    PKSLAM_CHECK_OPTION(!camera2, "camera2", "a rectified rig has no camera2");
    PKSLAM_CHECK_OPTION(camera1.distortion().empty() && camera1.type() == CameraType::kPinhole,
                        "camera1", "a rectified rig is an undistorted pinhole");
    PKSLAM_CHECK_OPTION(stereo_baseline_m && *stereo_baseline_m > 0, "stereo_baseline_m",
                        "required and positive for a rectified rig");
    PKSLAM_CHECK_OPTION(right_from_left.has_value(), "right_from_left",
                        "required for a rectified rig");
  } else {
    PKSLAM_CHECK_OPTION(!stereo_baseline_m || !camera2, "stereo_baseline_m",
                        "not with camera2 (the baseline comes from right_from_left)");
    PKSLAM_CHECK_OPTION(!stereo_baseline_m || *stereo_baseline_m > 0, "stereo_baseline_m", "{}",
                        *stereo_baseline_m);
    PKSLAM_CHECK_OPTION(!right_from_left || camera2, "right_from_left",
                        "stereo needs camera2 (or a rectified rig)");
  }
  if (right_from_left) {
    CheckRigid(*right_from_left, "right_from_left");
    PKSLAM_CHECK_OPTION(right_from_left->translation().norm() > 1e-6, "right_from_left",
                        "zero baseline");
  }
  PKSLAM_CHECK_OPTION(th_depth > 0 && std::isfinite(th_depth), "th_depth", "{}", th_depth);
  PKSLAM_CHECK_OPTION(imu.has_value() == body_from_cam0.has_value(), "imu/body_from_cam0",
                      "both or neither");
  PKSLAM_CHECK_OPTION(std::abs(time_offset_s) <= 1.0, "time_offset_s", "{} s", time_offset_s);
  if (imu) {
    CheckRigid(*body_from_cam0, "body_from_cam0");
    for (const auto& [name, value] :
         {std::pair{"imu.gyro_noise_density", imu->gyro_noise_density},
          std::pair{"imu.accel_noise_density", imu->accel_noise_density},
          std::pair{"imu.gyro_random_walk", imu->gyro_random_walk},
          std::pair{"imu.accel_random_walk", imu->accel_random_walk},
          std::pair{"imu.rate_hz", imu->rate_hz}}) {
      PKSLAM_CHECK_OPTION(value > 0 && std::isfinite(value), name, "{}", value);
    }
  }
  if (depth_map_factor) {
    PKSLAM_CHECK_OPTION(*depth_map_factor > 0, "depth_map_factor", "{}", *depth_map_factor);
  }
  if (depth_noise_k) {
    PKSLAM_CHECK_OPTION(*depth_noise_k > 0 && std::isfinite(*depth_noise_k), "depth_noise_k", "{}",
                        *depth_noise_k);
  }
  PKSLAM_CHECK_OPTION(orb.n_features > 0, "orb.n_features", "{}", orb.n_features);
  PKSLAM_CHECK_OPTION(orb.scale_factor > 1.0, "orb.scale_factor", "{}", orb.scale_factor);
  PKSLAM_CHECK_OPTION(orb.n_levels >= 1, "orb.n_levels", "{}", orb.n_levels);
  PKSLAM_CHECK_OPTION(orb.min_th_fast > 0 && orb.min_th_fast <= orb.ini_th_fast, "orb.min_th_fast",
                      "{} (iniThFAST {})", orb.min_th_fast, orb.ini_th_fast);
  for (const auto& [name, value] : keyframe) {
    PKSLAM_CHECK_OPTION(!name.empty() && std::isfinite(value), "keyframe." + name, "{}", value);
  }
}

// ---- Reader ----------------------------------------------------------------------------

Settings ReadOrbSlam3Settings(const std::filesystem::path& file) {
  const OpenCvYamlFile yaml(file);
  Settings s;

  // File.version is "1.0" in the v1.0 format (written quoted; accept a bare 1.0 too). Files
  // without it but with Camera.fx are ORB-SLAM2's or ORB-SLAM3's before v1.0.
  if (!yaml.Has("File.version") && yaml.Has("Camera.fx")) return ReadLegacyOrbSlamSettings(yaml);
  if (!yaml.Has("File.version")) {
    yaml.Fail("File.version",
              "missing: an ORB-SLAM3 v1.0 settings file has File.version: \"1.0\" (ORB-SLAM2 and "
              "ORB-SLAM3 <= 0.4 files, with Camera.fx, are read too; `pkslam settings convert` "
              "writes either as v1.0)");
  }
  std::string version;
  if (yaml.IsString("File.version")) {
    version = yaml.String("File.version");
  } else {
    version = fmt::format("{:.1f}", yaml.Double("File.version"));  // a bare number 1.0
  }
  if (version != "1.0") {
    yaml.Fail("File.version", fmt::format("unsupported version '{}' (expected \"1.0\")", version));
  }

  const std::string type_name = yaml.String("Camera.type");
  CameraType type = CameraType::kPinhole;
  if (type_name == "KannalaBrandt8") {
    type = CameraType::kKannalaBrandt8;
  } else if (type_name == "Rectified") {
    s.rectified_stereo = true;
  } else if (type_name != "PinHole") {
    yaml.Fail("Camera.type", fmt::format("unknown camera type '{}' (expected PinHole, "
                                         "KannalaBrandt8 or Rectified)",
                                         type_name));
  }
  for (const char* key : {"Camera.newWidth", "Camera.newHeight"}) {
    if (yaml.Has(key)) yaml.Fail(key, "image resizing is not supported; remove the key");
  }
  const int width = PositiveInt(yaml, "Camera.width");
  const int height = PositiveInt(yaml, "Camera.height");
  s.camera1 = ReadCamera(yaml, "Camera1", type, width, height);
  s.fps = Positive(yaml, "Camera.fps");
  if (s.fps > 10000) yaml.Fail("Camera.fps", fmt::format("must be at most 10000, found {}", s.fps));
  if (const auto rgb = yaml.OptionalInt("Camera.RGB")) {
    if (*rgb != 0 && *rgb != 1) yaml.Fail("Camera.RGB", "must be 0 (BGR) or 1 (RGB)");
    s.rgb_order = *rgb == 1;
  }

  if (s.rectified_stereo) {
    if (!s.camera1.distortion().empty()) {
      yaml.Fail("Camera1.k1", "a Rectified camera has no distortion coefficients");
    }
    s.stereo_baseline_m = Positive(yaml, "Stereo.b");
    s.right_from_left = SE3d(SO3d(), Eigen::Vector3d(-*s.stereo_baseline_m, 0, 0));
  } else {
    const bool has_camera2 = yaml.Has("Camera2.fx");
    const bool has_extrinsic = yaml.Has("Stereo.T_c1_c2");
    if (has_camera2 && !has_extrinsic) {
      yaml.Fail("Stereo.T_c1_c2", "missing (required with Camera2.*)");
    }
    if (has_extrinsic && !has_camera2) yaml.Fail("Camera2.fx", "missing (required for stereo)");
    if (has_camera2) {
      s.camera2 = ReadCamera(yaml, "Camera2", type, width, height);
      const SE3d left_from_right(yaml.RigidTransform("Stereo.T_c1_c2"));
      if (left_from_right.translation().norm() < 1e-6) {
        yaml.Fail("Stereo.T_c1_c2", "zero baseline");
      }
      s.right_from_left = left_from_right.Inverse();
      if (yaml.Has("Stereo.b")) {
        yaml.Fail("Stereo.b", "not used with Camera2 (the baseline comes from Stereo.T_c1_c2)");
      }
    } else if (yaml.Has("Stereo.b")) {
      s.stereo_baseline_m = Positive(yaml, "Stereo.b");  // RGB-D virtual baseline
    }
  }
  if (const auto th = yaml.OptionalDouble("Stereo.ThDepth")) {
    if (!(*th > 0)) yaml.Fail("Stereo.ThDepth", "must be positive");
    s.th_depth = *th;
  }

  bool any_imu = false;
  for (const std::string& key : yaml.Keys()) any_imu = any_imu || key.rfind("IMU.", 0) == 0;
  if (any_imu) {
    s.imu = ReadImuNoise(yaml);
    s.body_from_cam0 = SE3d(yaml.RigidTransform("IMU.T_b_c1"));
    if (const auto offset = yaml.OptionalDouble("IMU.TimeOffset")) {
      if (!(std::abs(*offset) <= 1.0)) {
        yaml.Fail("IMU.TimeOffset", fmt::format("must be within [-1, 1] s, found {}", *offset));
      }
      s.time_offset_s = *offset;
    }
    const char* scale_keys[3] = {"IMU.GyroScaleX", "IMU.GyroScaleY", "IMU.GyroScaleZ"};
    for (int i = 0; i < 3; ++i) {
      if (const auto k = yaml.OptionalDouble(scale_keys[i])) {
        if (!(std::abs(*k) <= 0.1)) {
          yaml.Fail(scale_keys[i],
                    fmt::format("must be within [-0.1, 0.1] (a fraction: 0.002 is 0.2%), found {}",
                                *k));
        }
        s.gyro_scale[i] = *k;
      }
    }
    if (yaml.Has("IMU.AccelAxes")) {
      const Eigen::MatrixXd e = yaml.Matrix("IMU.AccelAxes", 3, 3);
      for (int i = 0; i < 9; ++i) {
        const double v = e(i / 3, i % 3);
        if (!(std::abs(v) <= 0.2)) {
          yaml.Fail("IMU.AccelAxes",
                    fmt::format("entries must be within [-0.2, 0.2] (scale fractions, "
                                "misalignment in rad), found {} at row {}, col {}",
                                v, i / 3, i % 3));
        }
      }
      s.accel_axes = e;
    }
  }
  if (yaml.Has("RGBD.DepthMapFactor")) s.depth_map_factor = Positive(yaml, "RGBD.DepthMapFactor");
  if (yaml.Has("RGBD.DepthNoise")) s.depth_noise_k = Positive(yaml, "RGBD.DepthNoise");

  ReadOrbAndKeyframeKeys(yaml, &s);

  try {
    s.Check();
  } catch (const OptionError& e) {
    // Combinations the per-key checks above do not cover (e.g. ORB thresholds).
    throw InputError(file, fmt::format("inconsistent settings: {}", e.what()));
  }
  return s;
}

}  // namespace pkslam
