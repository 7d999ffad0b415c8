// Inertial run outputs: OUT/keyframes_imu.csv, one row per keyframe of the largest map
// (time, body velocity in the world, gyro and accel bias, whether estimated), so bias and
// velocity estimates can be compared with ground truth; OUT/trajectory_online_body.txt, the body
// poses as tracking estimated them at the time (TUM; each in the world of its moment, so a
// window between two IMU initialisation stages shows the scale and drift a live user had).
#pragma once

#include <filesystem>

#include "system/slam_system.h"

namespace pkslam {

// Writes nothing for non-inertial sensors.
void WriteInertialOutputs(const SlamSystem& system, const std::filesystem::path& out_dir);

}  // namespace pkslam
