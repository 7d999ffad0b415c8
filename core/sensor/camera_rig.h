// Calibration shared (immutably) by every Frame and KeyFrame of a run: the camera tracking
// works in, stereo/RGB-D baseline, the ORB scale pyramid, the undistorted image bounds and
// the body (IMU) extrinsics. Replaces ORB-SLAM's static Frame members.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>

#include "core/camera/camera_model.h"
#include "core/geometry/pinhole_intrinsics.h"
#include "core/geometry/se3.h"
#include "core/imu/imu_types.h"  // ImuNoise
#include "core/sensor/scale_pyramid.h"
#include "core/sensor/sensor.h"

namespace pkslam {

struct ImageBounds {
  double min_x = 0, max_x = 0, min_y = 0, max_y = 0;
  bool Contains(double x, double y) const {
    return x >= min_x && x < max_x && y >= min_y && y < max_y;
  }
};

struct CameraRig {
  Sensor sensor = Sensor::kStereo;
  // The camera tracking works in. Stereo: the rectified left camera (ideal pinhole).
  // Monocular / RGB-D: the raw camera (may be distorted; keypoints get undistorted).
  CameraModel camera;
  double fx = 0, fy = 0, cx = 0, cy = 0, inv_fx = 0, inv_fy = 0;
  // Stereo baseline (m) and bf = fx * baseline; for RGB-D a virtual baseline.
  double baseline = 0;
  double bf = 0;
  // The rectified left camera as a value (fx, fy, cx, cy, bf).
  PinholeIntrinsics intrinsics() const { return {fx, fy, cx, cy, bf}; }
  // Close/far split (m): points closer than this are "close" (ORB-SLAM's ThDepth*b).
  double th_depth = 0;
  // RGB-D depth image factor (pixel value / factor = metres).
  double depth_factor = 5000.0;
  // RGB-D depth noise: sigma_z = depth_noise_k * z^2 (m); Kinect v1 by default (Khoshelham &
  // Elberink 2012). Weights the depth (virtual disparity) residuals: depth_uncertainty.h.
  double depth_noise_k = 1.425e-3;
  ScalePyramid pyramid;
  // Bounds of the undistorted image (keypoint coordinates live in here).
  ImageBounds bounds;
  // Extrinsics of the tracking camera in the body (IMU) frame; identity without IMU.
  SE3d body_from_camera;
  std::optional<ImuNoise> imu;
  double fps = 20.0;

  // Fills fx..inv_fy and bounds from `camera` (undistorting the image corners/edges).
  void UpdateDerived();
};

}  // namespace pkslam
