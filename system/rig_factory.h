// Builds the CameraRig tracking works with from run Settings and the sensor (rectifying
// unrectified stereo pairs).
#pragma once

#include <memory>
#include <optional>

#include "core/camera/stereo_rectification.h"
#include "core/sensor/camera_rig.h"
#include "io/settings.h"

namespace pkslam {

struct RigSetup {
  std::shared_ptr<const CameraRig> rig;
  // Set when stereo images must be rectified before tracking.
  std::optional<StereoRectification> rectification;
};

// Throws OptionError when the settings do not support the sensor (e.g. stereo without a
// second camera, inertial without IMU calibration, RGB-D without a depth factor).
RigSetup MakeRig(const Settings& settings, Sensor sensor);

}  // namespace pkslam
