#include "estimators/optim/yaw_manifold.h"

#include <Eigen/Geometry>
#include <cmath>

namespace pkslam {
namespace {

Eigen::Quaterniond FromBlock(const double* q) { return Eigen::Quaterniond(q[3], q[0], q[1], q[2]); }

void ToBlock(const Eigen::Quaterniond& q, double* out) {
  out[0] = q.x();
  out[1] = q.y();
  out[2] = q.z();
  out[3] = q.w();
}

}  // namespace

bool YawQuaternionManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const double half = 0.5 * delta[0];
  const Eigen::Quaterniond yaw(std::cos(half), 0.0, 0.0, std::sin(half));
  ToBlock(FromBlock(x) * yaw, x_plus_delta);
  return true;
}

bool YawQuaternionManifold::PlusJacobian(const double* x, double* jacobian) const {
  // x * (0, 0, 1/2, 0) in (x, y, z, w) order: the derivative of x * q_z(delta) at delta = 0.
  jacobian[0] = 0.5 * x[1];
  jacobian[1] = -0.5 * x[0];
  jacobian[2] = 0.5 * x[3];
  jacobian[3] = -0.5 * x[2];
  return true;
}

bool YawQuaternionManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Eigen::Quaterniond r = FromBlock(x).conjugate() * FromBlock(y);
  if (r.w() < 0) r.coeffs() = -r.coeffs();
  y_minus_x[0] = 2.0 * std::atan2(r.z(), r.w());
  return true;
}

bool YawQuaternionManifold::MinusJacobian(const double* x, double* jacobian) const {
  // At y = x: delta ~ 2 * (x^-1 * y).z, linear in y.
  jacobian[0] = 2.0 * x[1];
  jacobian[1] = -2.0 * x[0];
  jacobian[2] = 2.0 * x[3];
  jacobian[3] = -2.0 * x[2];
  return true;
}

double ClosestYawAngle(const SO3d& rotation) {
  const Eigen::Matrix3d r = rotation.Matrix();
  return std::atan2(r(1, 0) - r(0, 1), r(0, 0) + r(1, 1));
}

SO3d ClosestYaw(const SO3d& rotation) {
  return SO3d::Exp(Eigen::Vector3d(0, 0, ClosestYawAngle(rotation)));
}

Sim3d ProjectToYawTranslation(const Sim3d& world_new_from_world_old,
                              const Eigen::Vector3d& anchor_world_old) {
  const SO3d yaw = ClosestYaw(world_new_from_world_old.so3());
  const Eigen::Vector3d anchor_new = world_new_from_world_old * anchor_world_old;
  return Sim3d(1.0, yaw, anchor_new - yaw * anchor_world_old);
}

double TiltAngle(const SO3d& world_new_from_world_old) {
  const Eigen::Vector3d z = world_new_from_world_old * Eigen::Vector3d::UnitZ();
  return std::atan2(z.head<2>().norm(), z.z());
}

}  // namespace pkslam
