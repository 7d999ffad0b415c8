// The sensor.yaml files of a EuRoC folder converted from a bag (rosbag_euroc.h): a bag holds no
// calibration, so it comes from run settings (an ORB-SLAM3 settings file):
//   cam0/sensor.yaml  Camera1, T_BS = IMU.T_b_c1 (identity without IMU keys), Camera.fps
//   cam1/sensor.yaml  Camera2 (Camera1 for "Rectified" stereo), T_BS = T_b_c1 * Stereo.T_c1_c2
//   imu0/sensor.yaml  T_BS identity (the IMU is the body), IMU.Frequency and noise densities;
//                     for settings without IMU keys the rate measured from imu0/data.csv and
//                     pkslam's default noise (core/imu/imu_types.h ImuNoise), as its comment says
// SettingsFromEuroc (settings_euroc.h) on the result gives back the settings' cameras, stereo
// extrinsic, camera-IMU extrinsic and IMU noise.
#pragma once

#include <filesystem>
#include <string>

#include "io/settings.h"

namespace pkslam {

// Writes the sensor.yaml of each stream folder present in `mav0` (cam0, cam1, imu0); `source`
// names the settings file in their comments. OptionError when cam1 is present but the settings
// describe no second camera; OutputError when a file cannot be written.
void WriteEurocSensorFiles(const Settings& settings, const std::filesystem::path& mav0,
                           const std::string& source);

}  // namespace pkslam
