// Ceres parameter blocks of inertial problems and their manifolds (Ceres 2.1 Manifold API).
//
// Body pose block: 7 doubles (qx, qy, qz, qw, tx, ty, tz) of world_from_body (T_wb), the same
// memory layout as the camera_from_world blocks of estimators/optim, updated by a RIGHT
// perturbation in the body frame (as ORB-SLAM3's VertexPose for the IMU body):
//   Plus(T_wb, delta) = T_wb * Exp(delta),   delta = [rho; phi]  (core/geometry/se3.h order),
// so to first order R_wb <- R_wb Exp(phi) and p_wb <- p_wb + R_wb rho. Equivalently
// body_from_world <- Exp(-delta) * body_from_world: a left perturbation of the inverse pose,
// which is what estimators/optim's SE3LeftManifold applies to camera_from_world blocks.
//
// Like SE3LeftManifold these manifolds use the "[I; 0] Jacobian trick": PlusJacobian returns a
// constant [I; 0] instead of d Plus / d delta in ambient (quaternion) coordinates, and every cost
// function on such a block (imu/imu_factors.h, imu/body_reprojection_error.h) writes the analytic
// d residual / d delta into the first TangentSize() columns of its ambient Jacobian and zeros
// into the rest. Do not put an AutoDiffCostFunction on the raw block numbers.
//
// Gravity direction block: 4 doubles (qx, qy, qz, qw) of R_wg (world_from_gravity), where the
// gravity frame has gravity along -z: g_w = R_wg * (0, 0, -G). Only the direction of gravity is
// observable, so the tangent is 2-D (rotations about the gravity frame's x and y axes, zero yaw):
//   Plus(R_wg, delta) = R_wg * Exp((delta_0, delta_1, 0)).
//
// Velocity (3: v_world), bias (3: gyro or accel) and log-scale (1) blocks are Euclidean.
#pragma once

#include <ceres/manifold.h>

#include <Eigen/Core>

#include "core/geometry/se3.h"
#include "core/geometry/so3.h"

namespace pkslam {

inline constexpr int kBodyPoseBlockSize = 7;
inline constexpr int kGravityDirectionBlockSize = 4;

// Fills / reads a 7-double world_from_body block (qx, qy, qz, qw, tx, ty, tz).
void BodyPoseToBlock(const SE3d& world_from_body, double* block);
SE3d BodyPoseFromBlock(const double* block);
// Fills / reads a 4-double world_from_gravity block (qx, qy, qz, qw).
void GravityRotationToBlock(const SO3d& world_from_gravity, double* block);
SO3d GravityRotationFromBlock(const double* block);

// R_wg with R_wg * (0, 0, -1) = gravity_direction_world (unit or not), taking the shortest
// rotation from the gravity frame's -z (ORB-SLAM3's construction; its yaw is arbitrary).
SO3d GravityRotationFromDirection(const Eigen::Vector3d& gravity_direction_world);

class BodyPoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kBodyPoseBlockSize; }
  int TangentSize() const override { return 6; }
  // x_plus_delta = x * Exp(delta).
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  // The constant [I6; 0] (7 x 6, row-major): see the file comment.
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool RightMultiplyByPlusJacobian(const double* x, int num_rows, const double* ambient_matrix,
                                   double* tangent_matrix) const override;
  // y_minus_x = Log(x^-1 * y), so that Minus(Plus(x, d), x) = d.
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  // The constant [I6 0] (6 x 7, row-major).
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

class GravityDirectionManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kGravityDirectionBlockSize; }
  int TangentSize() const override { return 2; }
  // x_plus_delta = x * Exp((delta_0, delta_1, 0)).
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  // The constant [I2; 0] (4 x 2, row-major).
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool RightMultiplyByPlusJacobian(const double* x, int num_rows, const double* ambient_matrix,
                                   double* tangent_matrix) const override;
  // The x and y components of Log(x^-1 * y) (exact inverse of Plus).
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  // The constant [I2 0] (2 x 4, row-major).
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

}  // namespace pkslam
