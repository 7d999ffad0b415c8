// Gravity-preserving (4-DoF) pieces of the inertial loop correction (issue 7).
//
// In an inertial map whose IMU is initialised the world frame is gravity-aligned: gravity is
// (0, 0, -g) (mapping/inertial_stages.cc rotates the map by world_from_gravity^-1 at the
// initialisation; the inertial BAs keep gravity_world = (0, 0, -g)). Roll and pitch of every
// keyframe are then observable through the accelerometer and must not be changed by a loop
// correction: only yaw (a rotation about the world z axis) and translation are free.
//
//  - YawQuaternionManifold: a Ceres manifold on the quaternion (x, y, z, w) of a
//    camera_from_world rotation R_cw whose only direction is R_cw * Rz(delta), i.e. the world
//    turns about its gravity axis, so R_cw * e_z (gravity seen from the camera) never changes.
//  - ClosestYaw: the rotation about z nearest (Frobenius) to a rotation.
//  - ProjectToYawTranslation: a world correction reduced to yaw + translation with scale 1,
//    keeping where it sends one anchor point (the loop query's camera centre).
#pragma once

#include <ceres/manifold.h>

#include <Eigen/Core>

#include "core/geometry/sim3.h"
#include "core/geometry/so3.h"

namespace pkslam {

class YawQuaternionManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 4; }
  int TangentSize() const override { return 1; }
  // x_plus_delta = x * q_z(delta) (Eigen order x, y, z, w).
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  // d Plus(x, delta) / d delta at delta = 0 (4 x 1).
  bool PlusJacobian(const double* x, double* jacobian) const override;
  // The angle about z of x^-1 * y (y assumed to differ from x by a yaw only).
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  // d Minus(y, x) / d y at y = x (1 x 4).
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

// The angle psi of the rotation Rz(psi) nearest to `rotation` (maximises trace(Rz^T R)).
double ClosestYawAngle(const SO3d& rotation);
SO3d ClosestYaw(const SO3d& rotation);

// world_new_from_world_old reduced to 4 DoF: rotation ClosestYaw(rotation), scale 1, and the
// translation that sends `anchor_world_old` where the full correction sends it.
Sim3d ProjectToYawTranslation(const Sim3d& world_new_from_world_old,
                              const Eigen::Vector3d& anchor_world_old);

// Roll/pitch part of a world correction: the angle (rad) between e_z and R * e_z.
double TiltAngle(const SO3d& world_new_from_world_old);

}  // namespace pkslam
