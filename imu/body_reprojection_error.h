// Reprojection residuals on a BODY pose block (world_from_body, BodyPoseManifold: right
// perturbation, [I6; 0] Jacobian convention) with a fixed body_from_camera, for inertial bundle
// adjustment and visual-inertial tracking, where the states are body (IMU) poses:
//   p_camera = camera_from_body * world_from_body^-1 * p_world.
// Residual definitions, whitening and the depth rule match estimators/optim/reprojection_error.h
// (the camera_from_world variants): r = sqrt(inv_sigma2) * (projection - observation),
//   mono:   (u, v)          = (fx x/z + cx, fy y/z + cy)
//   stereo: (u, v, u_right) with u_right = u - bf / z,
// and Evaluate returns false when the point is at depth <= kMinBodyReprojectionDepth (Ceres
// then rejects the step), so only add residuals whose point is in front at the initial estimate.
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <cmath>

#include "core/geometry/pinhole_intrinsics.h"
#include "core/geometry/se3.h"

namespace pkslam {

inline constexpr double kMinBodyReprojectionDepth = 1e-6;

// A pinhole camera rigidly mounted on the body: intrinsics of the rectified / undistorted image
// the keypoints live in, bf (stereo or RGB-D virtual baseline times fx; stereo residuals only)
// and the extrinsics (CameraRig::body_from_camera inverted).
struct BodyCamera {
  double fx = 0, fy = 0, cx = 0, cy = 0, bf = 0;
  SE3d camera_from_body;

  static BodyCamera Of(const PinholeIntrinsics& k, const SE3d& camera_from_body) {
    return {k.fx, k.fy, k.cx, k.cy, k.bf, camera_from_body};
  }
};

// Squared whitened errors at a body pose; +infinity when the point is not in front.
double BodyMonoChi2(const BodyCamera& camera, const SE3d& world_from_body,
                    const Eigen::Vector3d& p_world, const Eigen::Vector2d& uv, double inv_sigma2);
double BodyStereoChi2(const BodyCamera& camera, const SE3d& world_from_body,
                      const Eigen::Vector3d& p_world, const Eigen::Vector3d& uv_right,
                      double inv_sigma2);

// Body pose + point: parameters {world_from_body[7], p_world[3]}.
class BodyMonoReprojectionError final : public ceres::SizedCostFunction<2, 7, 3> {
 public:
  BodyMonoReprojectionError(const BodyCamera& camera, const Eigen::Vector2d& uv, double inv_sigma2)
      : camera_(camera), obs_(uv), sqrt_info_(std::sqrt(inv_sigma2)) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  BodyCamera camera_;
  Eigen::Vector2d obs_;
  double sqrt_info_;
};

// Body pose + point: parameters {world_from_body[7], p_world[3]}; observation (u, v, u_right).
class BodyStereoReprojectionError final : public ceres::SizedCostFunction<3, 7, 3> {
 public:
  BodyStereoReprojectionError(const BodyCamera& camera, const Eigen::Vector3d& uv_right,
                              double inv_sigma2)
      : camera_(camera), obs_(uv_right), sqrt_info_(std::sqrt(inv_sigma2)) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  BodyCamera camera_;
  Eigen::Vector3d obs_;
  double sqrt_info_;
};

// Body pose only (the point is a constant): parameters {world_from_body[7]}.
class BodyMonoPoseOnlyError final : public ceres::SizedCostFunction<2, 7> {
 public:
  BodyMonoPoseOnlyError(const BodyCamera& camera, const Eigen::Vector3d& p_world,
                        const Eigen::Vector2d& uv, double inv_sigma2)
      : camera_(camera), p_world_(p_world), obs_(uv), sqrt_info_(std::sqrt(inv_sigma2)) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  BodyCamera camera_;
  Eigen::Vector3d p_world_;
  Eigen::Vector2d obs_;
  double sqrt_info_;
};

// Body pose only: parameters {world_from_body[7]}; observation (u, v, u_right).
class BodyStereoPoseOnlyError final : public ceres::SizedCostFunction<3, 7> {
 public:
  BodyStereoPoseOnlyError(const BodyCamera& camera, const Eigen::Vector3d& p_world,
                          const Eigen::Vector3d& uv_right, double inv_sigma2)
      : camera_(camera), p_world_(p_world), obs_(uv_right), sqrt_info_(std::sqrt(inv_sigma2)) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  BodyCamera camera_;
  Eigen::Vector3d p_world_;
  Eigen::Vector3d obs_;
  double sqrt_info_;
};

}  // namespace pkslam
