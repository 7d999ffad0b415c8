#include "io/settings_legacy.h"

#include <fmt/format.h>

#include <Eigen/Core>

#include "core/util/error.h"
#include "core/util/log.h"
#include "io/settings_keys.h"

namespace pkslam {
namespace {

// Image size: Camera.width/height (ORB-SLAM3 0.4), LEFT.width/height (stereo files); ORB-SLAM2's
// monocular and RGB-D files carry none, and the size cannot be guessed from them.
std::pair<int, int> ImageSize(const OpenCvYamlFile& yaml) {
  for (const char* prefix : {"Camera", "LEFT"}) {
    const std::string w = std::string(prefix) + ".width";
    const std::string h = std::string(prefix) + ".height";
    if (yaml.Has(w) || yaml.Has(h)) return {PositiveInt(yaml, w), PositiveInt(yaml, h)};
  }
  yaml.Fail("Camera.width",
            "missing: this ORB-SLAM2-style file gives no image size; add Camera.width and "
            "Camera.height (EuRoC 752 x 480, TUM RGB-D 640 x 480)");
}

// LEFT.D / RIGHT.D: k1 k2 p1 p2 [k3] as a 1x5 or 1x4 matrix.
std::vector<double> Distortion(const OpenCvYamlFile& yaml, const std::string& key) {
  Eigen::MatrixXd d;
  try {
    d = yaml.Matrix(key, 1, 5);
  } catch (const InputError&) {
    d = yaml.Matrix(key, 1, 4);
  }
  std::vector<double> out(d.data(), d.data() + d.size());
  if (out.size() == 5 && out[4] == 0.0) out.pop_back();  // k3 = 0 is the 4-term model
  return out;
}

CameraModel RawCamera(const OpenCvYamlFile& yaml, const std::string& side, int width, int height) {
  const Eigen::MatrixXd k = yaml.Matrix(side + ".K", 3, 3);
  try {
    return CameraModel::Pinhole(width, height, k(0, 0), k(1, 1), k(0, 2), k(1, 2),
                                Distortion(yaml, side + ".D"));
  } catch (const OptionError& e) {
    yaml.Fail(side + ".K", fmt::format("invalid camera: {}", e.what()));
  }
}

// ORB-SLAM2's stereo rectification as an extrinsic: p_rect_left = R_L p_left, p_rect_right =
// R_R p_right, and the rectified right camera sits at +b along x (P_R(0, 3) = -fx b).
SE3d RightFromLeft(const OpenCvYamlFile& yaml) {
  const Eigen::Matrix3d r_left = yaml.Matrix("LEFT.R", 3, 3);
  const Eigen::Matrix3d r_right = yaml.Matrix("RIGHT.R", 3, 3);
  const Eigen::MatrixXd p_right = yaml.Matrix("RIGHT.P", 3, 4);
  const double baseline = -p_right(0, 3) / p_right(0, 0);
  if (!(baseline > 0)) {
    yaml.Fail("RIGHT.P", fmt::format("implies a baseline of {} m (expected P(0,3) = -fx * b < 0)",
                                     baseline));
  }
  const SO3d rect_left_from_left = SO3d::FitToMatrix(r_left);
  const SO3d rect_right_from_right = SO3d::FitToMatrix(r_right);
  const SE3d rect_right_from_rect_left(SO3d(), Eigen::Vector3d(-baseline, 0, 0));
  return SE3d(rect_right_from_right.Inverse(), Eigen::Vector3d::Zero()) *
         rect_right_from_rect_left * SE3d(rect_left_from_left, Eigen::Vector3d::Zero());
}

bool AllZero(const std::vector<double>& v) {
  for (double x : v)
    if (x != 0.0) return false;
  return true;
}

}  // namespace

Settings ReadLegacyOrbSlamSettings(const OpenCvYamlFile& yaml) {
  PKSLAM_LOG_WARN("{}: an ORB-SLAM2 / ORB-SLAM3 <= 0.4 settings file (no File.version), read by "
                  "the old keys; `pkslam settings convert` writes it in the v1.0 format",
                  yaml.file().string());
  Settings s;
  CameraType type = CameraType::kPinhole;
  if (const auto name = yaml.OptionalString("Camera.type")) {
    if (*name == "KannalaBrandt8") {
      type = CameraType::kKannalaBrandt8;
    } else if (*name != "PinHole") {
      yaml.Fail("Camera.type", fmt::format("unknown camera type '{}' (expected PinHole or "
                                           "KannalaBrandt8)",
                                           *name));
    }
  }
  const auto [width, height] = ImageSize(yaml);
  s.fps = Positive(yaml, "Camera.fps");
  if (const auto rgb = yaml.OptionalInt("Camera.RGB")) s.rgb_order = *rgb == 1;
  if (const auto th = yaml.OptionalDouble("ThDepth")) s.th_depth = *th;
  if (yaml.Has("DepthMapFactor")) s.depth_map_factor = Positive(yaml, "DepthMapFactor");

  if (yaml.Has("LEFT.K")) {  // stereo rectified at run time from the raw cameras
    s.camera1 = RawCamera(yaml, "LEFT", width, height);
    s.camera2 = RawCamera(yaml, "RIGHT", width, height);
    s.right_from_left = RightFromLeft(yaml);
  } else {
    s.camera1 = ReadCamera(yaml, "Camera", type, width, height);
    if (yaml.Has("Camera2.fx")) {
      s.camera2 = ReadCamera(yaml, "Camera2", type, width, height);
      if (!yaml.Has("Tlr")) yaml.Fail("Tlr", "missing (required with Camera2.*)");
      s.right_from_left = SE3d(yaml.RigidTransform("Tlr")).Inverse();
    } else if (yaml.Has("Camera.bf")) {
      const double baseline = Positive(yaml, "Camera.bf") / s.camera1.fx();
      s.stereo_baseline_m = baseline;
      if (!s.depth_map_factor) {  // pre-rectified stereo (KITTI): no RGB-D factor
        if (!AllZero(s.camera1.distortion())) {
          yaml.Fail("Camera.k1", "a pre-rectified stereo camera (Camera.bf, no LEFT.K) has no "
                                 "distortion");
        }
        s.rectified_stereo = true;
        s.camera1 = CameraModel::Pinhole(width, height, s.camera1.fx(), s.camera1.fy(),
                                         s.camera1.cx(), s.camera1.cy());
        s.right_from_left = SE3d(SO3d(), Eigen::Vector3d(-baseline, 0, 0));
      }
    }
  }
  bool any_imu = yaml.Has("Tbc");
  for (const std::string& key : yaml.Keys()) any_imu = any_imu || key.rfind("IMU.", 0) == 0;
  if (any_imu) {
    s.imu = ReadImuNoise(yaml);
    if (!yaml.Has("Tbc")) yaml.Fail("Tbc", "missing (the camera-IMU extrinsic, with IMU.*)");
    s.body_from_cam0 = SE3d(yaml.RigidTransform("Tbc"));
  }
  ReadOrbAndKeyframeKeys(yaml, &s);
  try {
    s.Check();
  } catch (const OptionError& e) {
    throw InputError(yaml.file(), fmt::format("inconsistent settings: {}", e.what()));
  }
  return s;
}

}  // namespace pkslam
