// Analytic reprojection residuals for Ceres on SE3LeftManifold pose blocks
// (estimators/optim/se3_manifold.h: 7 doubles of camera_from_world, left perturbation).
//
// Residuals are whitened: r = sqrt(inv_sigma2) * (projection - observation), so |r|^2 is the
// chi2 ORB-SLAM compares against 5.991 (mono, 2 DoF) / 7.815 (stereo, 3 DoF).
//   mono:   (u, v)          = (fx x/z + cx, fy y/z + cy)
//   stereo: (u, v, u_right) with u_right = u - bf / z
// with p_camera = (x, y, z) = camera_from_world * p_world.
// RGB-D observations (a keypoint plus a depth reading) pass the information of the measured
// disparity d = u - u_right = bf / depth (disparity_inv_sigma2 > 0, from the depth noise;
// core/sensor/depth_uncertainty.h): the third residual is then on the disparity,
//   sqrt(disparity_inv_sigma2) * (bf / z - d),
// independent of u (the depth reading does not share the keypoint's pixel error the way a
// stereo match's right coordinate does). disparity_inv_sigma2 = 0 keeps the stereo form.
//
// Pose Jacobians follow the [I6; 0] convention of se3_manifold.h: columns 0..5 hold
// d r / d delta for camera_from_world <- Exp(delta) * camera_from_world (delta = [rho; phi]),
// column 6 is zero. Point Jacobians are plain d r / d p_world.
//
// Points at depth <= kMinReprojectionDepth make Evaluate return false: Ceres then rejects the
// trial step. Callers must therefore only add residuals whose point is in front of the camera
// at the initial estimate (the optimisers classify the others as outliers up front).
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <cmath>

#include "core/geometry/pinhole_intrinsics.h"
#include "core/geometry/se3.h"

namespace pkslam {

inline constexpr double kMinReprojectionDepth = 1e-6;

// Intrinsics (core/geometry/pinhole_intrinsics.h) of the rectified / undistorted pinhole camera
// the keypoints live in; bf is used by stereo residuals only.

// Squared whitened errors (chi2) at a given pose; +infinity when the point is not in front of
// the camera (depth <= kMinReprojectionDepth).
double MonoChi2(const PinholeIntrinsics& k, const SE3d& camera_from_world,
                const Eigen::Vector3d& p_world, const Eigen::Vector2d& uv, double inv_sigma2);
double StereoChi2(const PinholeIntrinsics& k, const SE3d& camera_from_world,
                  const Eigen::Vector3d& p_world, const Eigen::Vector3d& uv_right,
                  double inv_sigma2, double disparity_inv_sigma2 = 0.0);

// Pose + point: parameters {pose[7], p_world[3]}.
class MonoReprojectionError final : public ceres::SizedCostFunction<2, 7, 3> {
 public:
  MonoReprojectionError(const PinholeIntrinsics& k, const Eigen::Vector2d& uv, double inv_sigma2)
      : k_(k), obs_(uv), sqrt_info_(std::sqrt(inv_sigma2)) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  PinholeIntrinsics k_;
  Eigen::Vector2d obs_;
  double sqrt_info_;
};

// Pose + point: parameters {pose[7], p_world[3]}; observation (u, v, u_right).
class StereoReprojectionError final : public ceres::SizedCostFunction<3, 7, 3> {
 public:
  StereoReprojectionError(const PinholeIntrinsics& k, const Eigen::Vector3d& uv_right,
                          double inv_sigma2, double disparity_inv_sigma2 = 0.0)
      : k_(k),
        obs_(uv_right),
        sqrt_info_(std::sqrt(inv_sigma2)),
        sqrt_info_disparity_(std::sqrt(disparity_inv_sigma2)) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  PinholeIntrinsics k_;
  Eigen::Vector3d obs_;
  double sqrt_info_;
  double sqrt_info_disparity_;
};

// Pose only (the point is a constant): parameters {pose[7]}.
class MonoPoseOnlyError final : public ceres::SizedCostFunction<2, 7> {
 public:
  MonoPoseOnlyError(const PinholeIntrinsics& k, const Eigen::Vector3d& p_world,
                    const Eigen::Vector2d& uv, double inv_sigma2)
      : k_(k), p_world_(p_world), obs_(uv), sqrt_info_(std::sqrt(inv_sigma2)) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  PinholeIntrinsics k_;
  Eigen::Vector3d p_world_;
  Eigen::Vector2d obs_;
  double sqrt_info_;
};

// Pose only (the point is a constant): parameters {pose[7]}; observation (u, v, u_right).
class StereoPoseOnlyError final : public ceres::SizedCostFunction<3, 7> {
 public:
  StereoPoseOnlyError(const PinholeIntrinsics& k, const Eigen::Vector3d& p_world,
                      const Eigen::Vector3d& uv_right, double inv_sigma2,
                      double disparity_inv_sigma2 = 0.0)
      : k_(k),
        p_world_(p_world),
        obs_(uv_right),
        sqrt_info_(std::sqrt(inv_sigma2)),
        sqrt_info_disparity_(std::sqrt(disparity_inv_sigma2)) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  PinholeIntrinsics k_;
  Eigen::Vector3d p_world_;
  Eigen::Vector3d obs_;
  double sqrt_info_;
  double sqrt_info_disparity_;
};

}  // namespace pkslam
