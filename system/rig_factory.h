// Builds the CameraRig tracking works with from run Settings and the sensor (rectifying
// unrectified stereo pairs): the settings' calibration (core/sensor/rig_calibration.h) and the
// rest of the rig, checked against what the sensor needs.
#pragma once

#include <memory>
#include <optional>

#include "core/sensor/rig_calibration.h"
#include "io/settings.h"

namespace pkslam {

// The calibration the settings state (cameras, extrinsics; time offset IMU.TimeOffset, 0 when
// absent). A rectified stereo pair (Camera.type Rectified) becomes two identical pinholes
// Stereo.b apart.
RigCalibration CalibrationFromSettings(const Settings& settings, Sensor sensor);
// `settings` with the cameras, extrinsics and time offset of `calibration` (an estimate): what
// OUT/calibration/settings.yaml holds. A rectified pair whose estimate is no longer the ideal pair
// becomes a two-camera rig.
Settings SettingsWithCalibration(Settings settings, const RigCalibration& calibration);
// Everything else of the rig.
RigShape ShapeFromSettings(const Settings& settings, Sensor sensor);

// Throws OptionError when the settings do not support the sensor (e.g. stereo without a
// second camera, inertial without IMU calibration, RGB-D without a depth factor).
RigSetup MakeRig(const Settings& settings, Sensor sensor);

}  // namespace pkslam
