#include "estimators/optim/se3_manifold.h"

#include <Eigen/Geometry>
#include <algorithm>

#include "core/util/error.h"

namespace pkslam {

void PoseToBlock(const SE3d& camera_from_world, double* block) {
  const Eigen::Quaterniond& q = camera_from_world.quaternion();
  block[0] = q.x();
  block[1] = q.y();
  block[2] = q.z();
  block[3] = q.w();
  block[4] = camera_from_world.translation().x();
  block[5] = camera_from_world.translation().y();
  block[6] = camera_from_world.translation().z();
}

SE3d PoseFromBlock(const double* block) {
  // Eigen's quaternion coefficient order is (x, y, z, w), the block's order.
  const Eigen::Quaterniond q(block[3], block[0], block[1], block[2]);
  return SE3d(q, Eigen::Vector3d(block[4], block[5], block[6]));
}

bool SE3LeftManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Eigen::Map<const Eigen::Matrix<double, 6, 1>> d(delta);
  PoseToBlock(SE3d::Exp(d) * PoseFromBlock(x), x_plus_delta);
  return true;
}

bool SE3LeftManifold::PlusJacobian(const double* /*x*/, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> j(jacobian);
  j.setZero();
  j.topRows<6>().setIdentity();
  return true;
}

bool SE3LeftManifold::RightMultiplyByPlusJacobian(const double* /*x*/, int num_rows,
                                                  const double* ambient_matrix,
                                                  double* tangent_matrix) const {
  for (int r = 0; r < num_rows; ++r) {
    for (int c = 0; c < 6; ++c) tangent_matrix[r * 6 + c] = ambient_matrix[r * 7 + c];
  }
  return true;
}

bool SE3LeftManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Eigen::Map<Eigen::Matrix<double, 6, 1>> out(y_minus_x);
  out = (PoseFromBlock(y) * PoseFromBlock(x).Inverse()).Log();
  return true;
}

bool SE3LeftManifold::MinusJacobian(const double* /*x*/, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> j(jacobian);
  j.setZero();
  j.leftCols<6>().setIdentity();
  return true;
}

SE3LeftSubsetManifold::SE3LeftSubsetManifold(const std::array<bool, 6>& held) {
  for (int i = 0; i < 6; ++i) {
    if (!held[static_cast<std::size_t>(i)]) free_.push_back(i);
  }
  PKSLAM_CHECK(!free_.empty(), "SE3LeftSubsetManifold: every axis held (hold the block instead)");
}

Eigen::MatrixXd SE3LeftSubsetManifold::Expansion() const {
  Eigen::MatrixXd e = Eigen::MatrixXd::Zero(6, TangentSize());
  for (int c = 0; c < TangentSize(); ++c) e(free_[static_cast<std::size_t>(c)], c) = 1.0;
  return e;
}

bool SE3LeftSubsetManifold::Plus(const double* x, const double* delta,
                                 double* x_plus_delta) const {
  Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
  for (int c = 0; c < TangentSize(); ++c) d[free_[static_cast<std::size_t>(c)]] = delta[c];
  PoseToBlock(SE3d::Exp(d) * PoseFromBlock(x), x_plus_delta);
  return true;
}

bool SE3LeftSubsetManifold::PlusJacobian(const double* /*x*/, double* jacobian) const {
  const int k = TangentSize();
  std::fill(jacobian, jacobian + kPoseBlockSize * k, 0.0);
  for (int c = 0; c < k; ++c) jacobian[free_[static_cast<std::size_t>(c)] * k + c] = 1.0;
  return true;
}

bool SE3LeftSubsetManifold::RightMultiplyByPlusJacobian(const double* /*x*/, int num_rows,
                                                        const double* ambient_matrix,
                                                        double* tangent_matrix) const {
  const int k = TangentSize();
  for (int r = 0; r < num_rows; ++r) {
    for (int c = 0; c < k; ++c) {
      tangent_matrix[r * k + c] =
          ambient_matrix[r * kPoseBlockSize + free_[static_cast<std::size_t>(c)]];
    }
  }
  return true;
}

bool SE3LeftSubsetManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const Eigen::Matrix<double, 6, 1> full = (PoseFromBlock(y) * PoseFromBlock(x).Inverse()).Log();
  for (int c = 0; c < TangentSize(); ++c) y_minus_x[c] = full[free_[static_cast<std::size_t>(c)]];
  return true;
}

bool SE3LeftSubsetManifold::MinusJacobian(const double* /*x*/, double* jacobian) const {
  const int k = TangentSize();
  std::fill(jacobian, jacobian + k * kPoseBlockSize, 0.0);
  for (int c = 0; c < k; ++c) jacobian[c * kPoseBlockSize + free_[static_cast<std::size_t>(c)]] = 1.0;
  return true;
}

}  // namespace pkslam
