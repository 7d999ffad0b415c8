#include "io/settings_keys.h"

#include <fmt/format.h>

#include <optional>
#include <vector>

#include "core/camera/camera_plausibility.h"
#include "core/util/error.h"

namespace pkslam {

double Positive(const OpenCvYamlFile& yaml, const std::string& key) {
  const double value = yaml.Double(key);
  if (!(value > 0)) yaml.Fail(key, fmt::format("must be positive, found {}", value));
  return value;
}

int PositiveInt(const OpenCvYamlFile& yaml, const std::string& key) {
  const int value = yaml.Int(key);
  if (value <= 0) yaml.Fail(key, fmt::format("must be a positive integer, found {}", value));
  return value;
}

CameraModel ReadCamera(const OpenCvYamlFile& yaml, const std::string& prefix, CameraType type,
                       int width, int height) {
  const double fx = Positive(yaml, prefix + ".fx");
  const double fy = Positive(yaml, prefix + ".fy");
  const double cx = yaml.Double(prefix + ".cx");
  const double cy = yaml.Double(prefix + ".cy");
  std::vector<double> distortion;
  if (type == CameraType::kKannalaBrandt8) {
    for (const char* k : {".k1", ".k2", ".k3", ".k4"})
      distortion.push_back(yaml.Double(prefix + k));
  } else if (yaml.Has(prefix + ".k1") || yaml.Has(prefix + ".p1")) {
    // ORB-SLAM3: k1 k2 p1 p2 come together; k3 is optional.
    for (const char* k : {".k1", ".k2", ".p1", ".p2"})
      distortion.push_back(yaml.Double(prefix + k));
    if (const auto k3 = yaml.OptionalDouble(prefix + ".k3")) distortion.push_back(*k3);
  }
  std::optional<CameraModel> camera;
  try {
    camera = type == CameraType::kKannalaBrandt8
                 ? CameraModel::KannalaBrandt8(
                       width, height, fx, fy, cx, cy,
                       {distortion[0], distortion[1], distortion[2], distortion[3]})
                 : CameraModel::Pinhole(width, height, fx, fy, cx, cy, std::move(distortion));
  } catch (const OptionError& e) {
    yaml.Fail(prefix + ".fx", fmt::format("invalid {} camera: {}", prefix, e.what()));
  }
  if (const auto bad = FindImplausibleParameter(*camera)) {
    const std::string key = prefix + "." + (bad->parameter == "distortion" ? "k1" : bad->parameter);
    yaml.Fail(key, "implausible calibration: " + bad->what);
  }
  return *camera;
}

ImuNoise ReadImuNoise(const OpenCvYamlFile& yaml) {
  ImuNoise imu;
  imu.gyro_noise_density = Positive(yaml, "IMU.NoiseGyro");
  imu.accel_noise_density = Positive(yaml, "IMU.NoiseAcc");
  imu.gyro_random_walk = Positive(yaml, "IMU.GyroWalk");
  imu.accel_random_walk = Positive(yaml, "IMU.AccWalk");
  imu.rate_hz = Positive(yaml, "IMU.Frequency");
  return imu;
}

void ReadOrbAndKeyframeKeys(const OpenCvYamlFile& yaml, Settings* settings) {
  Settings& s = *settings;
  // ORB settings within what an extractor can do: a feature count like 2e9 overflowed (the
  // initialisation extractor doubles it) into a negative count far from the file's line.
  const auto int_in = [&yaml](const std::string& key, int lo, int hi, int* out) {
    const auto v = yaml.OptionalInt(key);
    if (!v) return;
    if (*v < lo || *v > hi)
      yaml.Fail(key, fmt::format("must be in [{}, {}], found {}", lo, hi, *v));
    *out = *v;
  };
  int_in("ORBextractor.nFeatures", 1, 100000, &s.orb.n_features);
  int_in("ORBextractor.nLevels", 1, 32, &s.orb.n_levels);
  int_in("ORBextractor.iniThFAST", 1, 255, &s.orb.ini_th_fast);
  int_in("ORBextractor.minThFAST", 1, 255, &s.orb.min_th_fast);
  if (const auto v = yaml.OptionalDouble("ORBextractor.scaleFactor")) {
    if (!(*v > 1.0 && *v <= 4.0)) {
      yaml.Fail("ORBextractor.scaleFactor", fmt::format("must be in (1, 4], found {}", *v));
    }
    s.orb.scale_factor = *v;
  }

  const std::string keyframe_prefix = "Keyframe.";
  for (const std::string& key : yaml.Keys()) {
    if (key.rfind(keyframe_prefix, 0) != 0) continue;
    if (key.size() == keyframe_prefix.size()) yaml.Fail(key, "empty parameter name");
    s.keyframe[key.substr(keyframe_prefix.size())] = yaml.Double(key);
  }
}

}  // namespace pkslam
