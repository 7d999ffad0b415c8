// Pinhole intrinsics of undistorted keypoint coordinates (the camera ORB-SLAM-style geometry
// works in: Frame/KeyFrame keypoints_undistorted() are ideal-pinhole pixels of the rig's fx,
// fy, cx, cy, also for fisheye rigs). Templated projection so Ceres Jets can use it.
#pragma once

#include <Eigen/Core>

namespace pkslam {

struct PinholeIntrinsics {
  double fx = 1, fy = 1, cx = 0, cy = 0;
  // Stereo (or RGB-D virtual) baseline times fx; used by stereo residuals only.
  double bf = 0;

  // uv of a camera-frame point (no check of z: callers reject z <= 0 themselves).
  template <typename T>
  Eigen::Matrix<T, 2, 1> Project(const Eigen::Matrix<T, 3, 1>& p_camera) const {
    const T inv_z = T(1) / p_camera.z();
    return {T(fx) * p_camera.x() * inv_z + T(cx), T(fy) * p_camera.y() * inv_z + T(cy)};
  }
  // Unit bearing vector of an undistorted pixel.
  Eigen::Vector3d Bearing(const Eigen::Vector2d& uv) const {
    return Eigen::Vector3d((uv.x() - cx) / fx, (uv.y() - cy) / fy, 1.0).normalized();
  }
};

}  // namespace pkslam
