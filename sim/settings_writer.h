// ORB-SLAM3-format settings files (File.version "1.0") for simulated sequences, so pkslam and
// ORB-SLAM3 can run them directly. Private to sim/ until io/settings.h (WriteOrbSlam3Settings)
// lands on main; then this delegates to it.
#pragma once

#include <filesystem>

#include "sim/euroc_writer.h"
#include "sim/imu_simulator.h"

namespace pkslam::sim {

// Stereo (+ IMU when imu != nullptr) settings for cam0/cam1 of a EuRoC-layout sequence.
void WriteStereoSettings(const std::filesystem::path& file, const CameraRig& left,
                         const CameraRig& right, const ImuOptions* imu);

// RGB-D settings (TUM layout): pinhole camera, depth map factor.
void WriteRgbdSettings(const std::filesystem::path& file, const CameraRig& camera,
                       double depth_factor);

}  // namespace pkslam::sim
