// The key readers the ORB-SLAM settings formats share (v1.0 in settings.cc, ORB-SLAM2 and
// ORB-SLAM3 <= 0.4 in settings_legacy.cc). Each failure is an InputError naming the file, the
// key and its line.
#pragma once

#include <string>

#include "core/camera/camera_model.h"
#include "io/opencv_yaml.h"
#include "io/settings.h"

namespace pkslam {

double Positive(const OpenCvYamlFile& yaml, const std::string& key);
int PositiveInt(const OpenCvYamlFile& yaml, const std::string& key);

// PREFIX.fx, fy, cx, cy and the distortion (PinHole: k1 k2 p1 p2 [k3], all or none;
// KannalaBrandt8: k1..k4), checked for plausibility (core/camera/camera_plausibility.h).
CameraModel ReadCamera(const OpenCvYamlFile& yaml, const std::string& prefix, CameraType type,
                       int width, int height);

// IMU.NoiseGyro, NoiseAcc, GyroWalk, AccWalk, Frequency (the same names since ORB-SLAM3 0.3).
ImuNoise ReadImuNoise(const OpenCvYamlFile& yaml);

// ORBextractor.* within what an extractor can do, and Keyframe.* selector parameters.
void ReadOrbAndKeyframeKeys(const OpenCvYamlFile& yaml, Settings* settings);

}  // namespace pkslam
