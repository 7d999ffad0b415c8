// ORB-SLAM2 and ORB-SLAM3 <= 0.4 settings files (no File.version; Camera.fx, LEFT.K, Tlr, Tbc),
// read into the same Settings as v1.0 files so an old file gives the same run as its v1.0
// translation. `pkslam settings convert` writes that translation.
//
// What maps to what: Camera.fx/fy/cx/cy + k1 k2 p1 p2 [k3] (or Camera.k1..k4 with Camera.type
// KannalaBrandt8) -> Camera1.*; stereo with run-time rectification (LEFT.K, LEFT.D, LEFT.R,
// RIGHT.K, RIGHT.D, RIGHT.R, RIGHT.P) -> the raw cameras and the extrinsic those rotations and
// the right projection imply (Camera.* there is the rectified camera and is not used); Camera2.*
// + Tlr (0.4, right to left) -> Camera2.* + Stereo.T_c1_c2; Camera.bf with DepthMapFactor -> an
// RGB-D virtual baseline, without it (pre-rectified stereo, KITTI) -> Camera.type Rectified with
// Stereo.b = bf / fx; ThDepth -> Stereo.ThDepth; DepthMapFactor -> RGBD.DepthMapFactor; Tbc ->
// IMU.T_b_c1; IMU.*, ORBextractor.*, Camera.fps, Camera.RGB unchanged.
#pragma once

#include "io/opencv_yaml.h"
#include "io/settings.h"

namespace pkslam {

Settings ReadLegacyOrbSlamSettings(const OpenCvYamlFile& yaml);

}  // namespace pkslam
