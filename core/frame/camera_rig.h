// Calibration shared (immutably) by every Frame and KeyFrame of a run: the camera tracking
// works in, stereo/RGB-D baseline, the ORB scale pyramid, the undistorted image bounds and
// the body (IMU) extrinsics. Replaces ORB-SLAM's static Frame members.
#pragma once

#include <memory>
#include <optional>

#include <Eigen/Core>

#include "core/camera/camera_model.h"
#include "core/frame/scale_pyramid.h"
#include "core/frame/sensor.h"
#include "core/geometry/se3.h"

namespace pkslam {

// Noise model of the IMU (continuous-time densities, as in EuRoC's sensor.yaml / ORB-SLAM3's
// settings) and its rate.
struct ImuNoise {
  double gyro_noise_density = 1.7e-4;   // rad/s/sqrt(Hz)
  double accel_noise_density = 2.0e-3;  // m/s^2/sqrt(Hz)
  double gyro_random_walk = 1.9393e-5;  // rad/s^2/sqrt(Hz)
  double accel_random_walk = 3.0e-3;    // m/s^3/sqrt(Hz)
  double rate_hz = 200.0;
};

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
  // Close/far split (m): points closer than this are "close" (ORB-SLAM's ThDepth*b).
  double th_depth = 0;
  // RGB-D depth image factor (pixel value / factor = metres).
  double depth_factor = 5000.0;
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
