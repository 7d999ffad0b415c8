// Settings straight from a EuRoC dataset's sensor.yaml files, so EuRoC runs need no settings
// file: camera1/camera2 from cam0/cam1 intrinsics and distortion, right_from_left =
// T_BS(cam1)^-1 * T_BS(cam0), body_from_cam0 = T_BS(imu0)^-1 * T_BS(cam0) (the IMU frame is
// the body; T_BS(imu0) is the identity on EuRoC), the time offset from cam0's optional
// timeshift_cam_imu (Kalibr's key; 0 without it), IMU noise from imu0, and
// ORB-SLAM3's EuRoC stereo-inertial defaults for the rest (ORB 1200 / 1.2 / 8 / 20 / 7,
// Stereo.ThDepth 60).
#pragma once

#include "io/euroc_dataset.h"
#include "io/settings.h"

namespace pkslam {

// Uses cam1 when present (stereo) and imu0 when present (inertial). Throws InputError when
// cam0 and cam1 disagree on resolution, rate or camera model.
Settings SettingsFromEuroc(const EurocDataset& dataset);

}  // namespace pkslam
