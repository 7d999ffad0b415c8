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

}  // namespace

void WriteEurocSensorFiles(const Settings& settings, const fs::path& mav0,
                           const std::string& source) {
  const SE3d body_from_cam0 = settings.body_from_cam0.value_or(SE3d());
  const std::string comment = fmt::format("from {} (pkslam convert)", source);
  WriteFileAtomically(
      mav0 / "cam0" / "sensor.yaml",
      EurocCameraSensorYaml(EurocCameraSensorOf(settings.camera1, body_from_cam0, settings.fps),
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
            EurocCameraSensorOf(settings.camera2.value_or(settings.camera1), body_from_cam1,
                                settings.fps),
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
    WriteFileAtomically(mav0 / "imu0" / "sensor.yaml", EurocImuSensorYaml(EurocImuSensorOf(noise), imu_comment));
  }
}

}  // namespace pkslam
