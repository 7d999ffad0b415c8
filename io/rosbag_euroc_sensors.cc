#include "io/rosbag_euroc_sensors.h"

#include <fmt/format.h>

#include <cmath>

#include "core/util/error.h"
#include "core/util/output_file.h"
#include "io/dataset_common.h"
#include "io/euroc_dataset.h"
#include "io/euroc_sensor.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

EurocCameraSensor SensorOf(const CameraModel& camera, const SE3d& body_from_camera,
                           double rate_hz) {
  EurocCameraSensor s;
  s.body_from_camera = body_from_camera;
  s.rate_hz = rate_hz;
  s.width = camera.width();
  s.height = camera.height();
  s.camera_model = "pinhole";
  s.intrinsics = {camera.fx(), camera.fy(), camera.cx(), camera.cy()};
  s.distortion_model =
      camera.type() == CameraType::kKannalaBrandt8 ? "equidistant" : "radial-tangential";
  s.distortion_coefficients = camera.distortion();
  return s;
}

std::string ImuSensorYaml(const ImuNoise& noise, const std::string& comment) {
  return fmt::format(
      "%YAML:1.0\n# General sensor definitions.\nsensor_type: imu\ncomment: {}\n\n"
      "# Sensor extrinsics wrt. the body-frame.\nT_BS:\n  cols: 4\n  rows: 4\n"
      "  data: [1.0, 0.0, 0.0, 0.0,\n         0.0, 1.0, 0.0, 0.0,\n"
      "         0.0, 0.0, 1.0, 0.0,\n         0.0, 0.0, 0.0, 1.0]\n"
      "rate_hz: {}\n\n# inertial sensor noise model parameters (static)\n"
      "gyroscope_noise_density: {}     # [ rad / s / sqrt(Hz) ]\n"
      "gyroscope_random_walk: {}       # [ rad / s^2 / sqrt(Hz) ]\n"
      "accelerometer_noise_density: {} # [ m / s^2 / sqrt(Hz) ]\n"
      "accelerometer_random_walk: {}   # [ m / s^3 / sqrt(Hz) ]\n",
      comment, noise.rate_hz, noise.gyro_noise_density, noise.gyro_random_walk,
      noise.accel_noise_density, noise.accel_random_walk);
}

}  // namespace

void WriteEurocSensorFiles(const Settings& settings, const fs::path& mav0,
                           const std::string& source) {
  const SE3d body_from_cam0 = settings.body_from_cam0.value_or(SE3d());
  const std::string comment = fmt::format("from {} (pkslam convert)", source);
  WriteFileAtomically(
      mav0 / "cam0" / "sensor.yaml",
      EurocCameraSensorYaml(SensorOf(settings.camera1, body_from_cam0, settings.fps),
                            comment + ", Camera1"));
  if (fs::is_directory(mav0 / "cam1")) {
    if (!settings.right_from_left) {
      throw OptionError(
          fmt::format("{} describes one camera (no Camera2 / Stereo.T_c1_c2 / "
                      "Stereo.b): cam1 needs a stereo settings file",
                      source));
    }
    const SE3d body_from_cam1 = body_from_cam0 * settings.right_from_left->Inverse();
    WriteFileAtomically(
        mav0 / "cam1" / "sensor.yaml",
        EurocCameraSensorYaml(
            SensorOf(settings.camera2.value_or(settings.camera1), body_from_cam1, settings.fps),
            comment + (settings.camera2 ? ", Camera2" : ", rectified pair")));
  }
  if (fs::is_directory(mav0 / "imu0")) {
    ImuNoise noise;
    std::string imu_comment = comment + ", IMU";
    if (settings.imu) {
      noise = *settings.imu;
    } else {
      const std::vector<ImuSample> samples = ReadEurocImu(mav0 / "imu0" / "data.csv");
      const double rate = MeasuredRateHz(samples.front().t_ns, samples.back().t_ns, samples.size());
      noise.rate_hz = rate > 0 ? std::round(rate) : noise.rate_hz;
      imu_comment = fmt::format(
          "{} has no IMU keys, so the rate is measured from data.csv and "
          "the noise is pkslam's default (EuRoC's ADIS16448)",
          source);
    }
    WriteFileAtomically(mav0 / "imu0" / "sensor.yaml", ImuSensorYaml(noise, imu_comment));
  }
}

}  // namespace pkslam
