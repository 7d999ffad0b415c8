#include "imu/imu_manifolds.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

namespace pkslam {
namespace {

// tangent = the first `tangent_size` columns of ambient (row-major num_rows x ambient_size).
void FirstColumns(int num_rows, int ambient_size, int tangent_size, const double* ambient,
                  double* tangent) {
  for (int r = 0; r < num_rows; ++r) {
    for (int c = 0; c < tangent_size; ++c) {
      tangent[r * tangent_size + c] = ambient[r * ambient_size + c];
    }
  }
}

// Row-major rows x cols matrix [I; 0] (rows >= cols) or [I 0] (rows < cols).
void IdentityPadded(int rows, int cols, double* m) {
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) m[r * cols + c] = r == c ? 1.0 : 0.0;
  }
}

}  // namespace

void BodyPoseToBlock(const SE3d& world_from_body, double* block) {
  const Eigen::Quaterniond& q = world_from_body.quaternion();
  block[0] = q.x();
  block[1] = q.y();
  block[2] = q.z();
  block[3] = q.w();
  block[4] = world_from_body.translation().x();
  block[5] = world_from_body.translation().y();
  block[6] = world_from_body.translation().z();
}

SE3d BodyPoseFromBlock(const double* block) {
  const Eigen::Quaterniond q(block[3], block[0], block[1], block[2]);
  return SE3d(q, Eigen::Vector3d(block[4], block[5], block[6]));
}

void GravityRotationToBlock(const SO3d& world_from_gravity, double* block) {
  const Eigen::Quaterniond& q = world_from_gravity.quaternion();
  block[0] = q.x();
  block[1] = q.y();
  block[2] = q.z();
  block[3] = q.w();
}

SO3d GravityRotationFromBlock(const double* block) {
  return SO3d(Eigen::Quaterniond(block[3], block[0], block[1], block[2]));
}

SO3d GravityRotationFromDirection(const Eigen::Vector3d& gravity_direction_world) {
  const Eigen::Vector3d down_g(0, 0, -1);
  const Eigen::Vector3d dir = gravity_direction_world.normalized();
  const Eigen::Vector3d axis = down_g.cross(dir);
  const double sin_angle = axis.norm();
  const double angle = std::atan2(sin_angle, down_g.dot(dir));
  if (sin_angle < 1e-12) {
    // Parallel: identity, or a half turn about x when gravity points along +z.
    return angle < 1.0 ? SO3d() : SO3d::Exp(Eigen::Vector3d(std::numbers::pi, 0, 0));
  }
  return SO3d::Exp(axis / sin_angle * angle);
}

bool BodyPoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Map<const Eigen::Matrix<double, 6, 1>> d(delta);
  BodyPoseToBlock(BodyPoseFromBlock(x) * SE3d::Exp(d), x_plus_delta);
  return true;
}

bool BodyPoseManifold::PlusJacobian(const double* /*x*/, double* jacobian) const {
  IdentityPadded(7, 6, jacobian);
  return true;
}

bool BodyPoseManifold::RightMultiplyByPlusJacobian(const double* /*x*/, int num_rows,
                                                   const double* ambient_matrix,
                                                   double* tangent_matrix) const {
  FirstColumns(num_rows, 7, 6, ambient_matrix, tangent_matrix);
  return true;
}

bool BodyPoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Eigen::Map<Eigen::Matrix<double, 6, 1>> out(y_minus_x);
  out = (BodyPoseFromBlock(x).Inverse() * BodyPoseFromBlock(y)).Log();
  return true;
}

bool BodyPoseManifold::MinusJacobian(const double* /*x*/, double* jacobian) const {
  IdentityPadded(6, 7, jacobian);
  return true;
}

bool GravityDirectionManifold::Plus(const double* x, const double* delta,
                                    double* x_plus_delta) const {
  GravityRotationToBlock(
      GravityRotationFromBlock(x) * SO3d::Exp(Eigen::Vector3d(delta[0], delta[1], 0.0)),
      x_plus_delta);
  return true;
}

bool GravityDirectionManifold::PlusJacobian(const double* /*x*/, double* jacobian) const {
  IdentityPadded(4, 2, jacobian);
  return true;
}

bool GravityDirectionManifold::RightMultiplyByPlusJacobian(const double* /*x*/, int num_rows,
                                                           const double* ambient_matrix,
                                                           double* tangent_matrix) const {
  FirstColumns(num_rows, 4, 2, ambient_matrix, tangent_matrix);
  return true;
}

bool GravityDirectionManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const Eigen::Vector3d d =
      (GravityRotationFromBlock(x).Inverse() * GravityRotationFromBlock(y)).Log();
  y_minus_x[0] = d.x();
  y_minus_x[1] = d.y();
  return true;
}

bool GravityDirectionManifold::MinusJacobian(const double* /*x*/, double* jacobian) const {
  IdentityPadded(2, 4, jacobian);
  return true;
}

}  // namespace pkslam
