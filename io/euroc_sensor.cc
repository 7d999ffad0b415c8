#include "io/euroc_sensor.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "io/opencv_yaml.h"

namespace pkslam {
namespace {

double PositiveDouble(const OpenCvYamlFile& yaml, const std::string& key) {
  const double value = yaml.Double(key);
  if (!(value > 0)) yaml.Fail(key, fmt::format("must be positive, found {}", value));
  return value;
}

}  // namespace

EurocCameraSensor ReadEurocCameraSensor(const std::filesystem::path& sensor_yaml) {
  const OpenCvYamlFile yaml(sensor_yaml);
  EurocCameraSensor camera;
  camera.body_from_camera = SE3d(yaml.RigidTransform("T_BS"));
  camera.rate_hz = PositiveDouble(yaml, "rate_hz");
  const std::vector<double> resolution = yaml.DoubleSequence("resolution", 2);
  // Range first: converting a double beyond int (1e10) to int is undefined behaviour.
  const auto positive_int = [](double v) {
    return v >= 1 && v <= std::numeric_limits<int>::max() && v == std::floor(v);
  };
  if (!positive_int(resolution[0]) || !positive_int(resolution[1])) {
    yaml.Fail("resolution", "expected two positive integers [width, height]");
  }
  camera.width = static_cast<int>(resolution[0]);
  camera.height = static_cast<int>(resolution[1]);
  camera.camera_model = yaml.String("camera_model");
  if (camera.camera_model != "pinhole") {
    yaml.Fail("camera_model",
              fmt::format("unsupported model '{}' (expected pinhole)", camera.camera_model));
  }
  const std::vector<double> intrinsics = yaml.DoubleSequence("intrinsics", 4);
  for (int i = 0; i < 4; ++i) camera.intrinsics[i] = intrinsics[i];
  if (!(intrinsics[0] > 0 && intrinsics[1] > 0)) {
    yaml.Fail("intrinsics", "focal lengths fu, fv must be positive");
  }
  camera.distortion_model = yaml.String("distortion_model");
  camera.distortion_coefficients = yaml.DoubleSequence("distortion_coefficients");
  const std::size_t n = camera.distortion_coefficients.size();
  if (camera.distortion_model == "radial-tangential") {
    if (n != 4 && n != 5) {
      yaml.Fail("distortion_coefficients",
                fmt::format("radial-tangential needs 4 or 5 coefficients, found {}", n));
    }
  } else if (camera.distortion_model == "equidistant") {
    if (n != 4) {
      yaml.Fail("distortion_coefficients",
                fmt::format("equidistant needs 4 coefficients, found {}", n));
    }
  } else {
    yaml.Fail("distortion_model",
              fmt::format("unsupported model '{}' (expected radial-tangential or equidistant)",
                          camera.distortion_model));
  }
  return camera;
}

EurocImuSensor ReadEurocImuSensor(const std::filesystem::path& sensor_yaml) {
  const OpenCvYamlFile yaml(sensor_yaml);
  EurocImuSensor imu;
  imu.body_from_imu = SE3d(yaml.RigidTransform("T_BS"));
  imu.rate_hz = PositiveDouble(yaml, "rate_hz");
  imu.gyroscope_noise_density = PositiveDouble(yaml, "gyroscope_noise_density");
  imu.gyroscope_random_walk = PositiveDouble(yaml, "gyroscope_random_walk");
  imu.accelerometer_noise_density = PositiveDouble(yaml, "accelerometer_noise_density");
  imu.accelerometer_random_walk = PositiveDouble(yaml, "accelerometer_random_walk");
  return imu;
}

}  // namespace pkslam
