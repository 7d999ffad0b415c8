#include "io/settings_euroc.h"

#include <fmt/format.h>

#include <optional>

#include "core/camera/camera_plausibility.h"
#include "core/util/error.h"
#include "io/opencv_yaml.h"

namespace pkslam {
namespace {

CameraModel CameraOf(const EurocCameraSensor& sensor, const std::filesystem::path& yaml) {
  const auto& k = sensor.intrinsics;
  const auto& d = sensor.distortion_coefficients;
  std::optional<CameraModel> camera;
  try {
    camera = sensor.distortion_model == "equidistant"
                 ? CameraModel::KannalaBrandt8(sensor.width, sensor.height, k[0], k[1], k[2],
                                               k[3], {d[0], d[1], d[2], d[3]})
                 : CameraModel::Pinhole(sensor.width, sensor.height, k[0], k[1], k[2], k[3], d);
  } catch (const OptionError& e) {
    throw InputError(yaml, fmt::format("invalid camera calibration: {}", e.what()));
  }
  if (const auto bad = FindImplausibleParameter(*camera)) {
    const bool distortion = bad->parameter == "distortion";
    const std::string key = distortion ? "distortion_coefficients" : "intrinsics";
    throw InputError(yaml, OpenCvYamlFile(yaml).LineOf(key),
                     fmt::format("implausible calibration ({}{}): {}", key,
                                 distortion ? "" : " [fu, fv, cu, cv]", bad->what));
  }
  return *camera;
}

}  // namespace

Settings SettingsFromEuroc(const EurocDataset& dataset) {
  Settings s;
  const EurocCameraSensor& cam0 = dataset.cam0_sensor();
  s.camera1 = CameraOf(cam0, dataset.mav0() / "cam0" / "sensor.yaml");
  s.fps = cam0.rate_hz;
  if (dataset.has_cam1()) {
    const EurocCameraSensor& cam1 = dataset.cam1_sensor();
    const std::filesystem::path cam1_yaml = dataset.mav0() / "cam1" / "sensor.yaml";
    if (cam1.width != cam0.width || cam1.height != cam0.height) {
      throw InputError(cam1_yaml, fmt::format("resolution {}x{} differs from cam0's {}x{}",
                                              cam1.width, cam1.height, cam0.width, cam0.height));
    }
    if (cam1.rate_hz != cam0.rate_hz) {
      throw InputError(
          cam1_yaml, fmt::format("rate_hz {} differs from cam0's {}", cam1.rate_hz, cam0.rate_hz));
    }
    if (cam1.distortion_model != cam0.distortion_model) {
      throw InputError(cam1_yaml, "distortion_model differs from cam0's");
    }
    s.camera2 = CameraOf(cam1, cam1_yaml);
    // p_cam1 = T_BS1^-1 * T_BS0 * p_cam0.
    s.right_from_left = cam1.body_from_camera.Inverse() * cam0.body_from_camera;
    if (s.right_from_left->translation().norm() <= 1e-6) {
      throw InputError(cam1_yaml,
                       "T_BS places cam1 where cam0 is (zero stereo baseline): "
                       "check cam1's T_BS against cam0's");
    }
  }
  if (dataset.has_imu()) {
    const EurocImuSensor& imu = dataset.imu_sensor();
    ImuNoise noise;
    noise.gyro_noise_density = imu.gyroscope_noise_density;
    noise.accel_noise_density = imu.accelerometer_noise_density;
    noise.gyro_random_walk = imu.gyroscope_random_walk;
    noise.accel_random_walk = imu.accelerometer_random_walk;
    noise.rate_hz = imu.rate_hz;
    s.imu = noise;
    // The camera's T_BS is relative to the body frame; the IMU may be offset from it.
    s.body_from_cam0 = imu.body_from_imu.Inverse() * cam0.body_from_camera;
    // Kalibr's timeshift_cam_imu when cam0's file has it (pkslam's calibration estimates).
    s.time_offset_s = cam0.timeshift_cam_imu;
    s.gyro_scale = imu.gyroscope_scale_error;
    s.accel_axes = imu.accelerometer_axis_errors;
  }
  s.th_depth = 60;
  s.orb = OrbExtractorSettings{};  // 1200 features, 1.2, 8 levels, FAST 20 / 7
  s.Check();
  return s;
}

}  // namespace pkslam
