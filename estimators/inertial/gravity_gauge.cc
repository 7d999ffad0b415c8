#include "estimators/inertial/gravity_gauge.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace pkslam {

double TiltObservability(const std::vector<SO3d>& world_from_body) {
  if (world_from_body.size() < 2) return 0.0;
  // [e_z]x on horizontal d = (d_x, d_y, 0): e_z x d = (-d_y, d_x, 0).
  Eigen::Matrix<double, 3, 2> cross_z;
  cross_z << 0, -1, 1, 0, 0, 0;
  std::vector<Eigen::Matrix<double, 3, 2>> g;
  g.reserve(world_from_body.size());
  Eigen::Matrix<double, 3, 2> mean = Eigen::Matrix<double, 3, 2>::Zero();
  for (const SO3d& r : world_from_body) {
    g.push_back(r.Inverse().Matrix() * cross_z);
    mean += g.back();
  }
  mean /= static_cast<double>(g.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const auto& gi : g) scatter += (gi - mean).transpose() * (gi - mean);
  scatter /= static_cast<double>(g.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(scatter);
  return std::clamp(es.eigenvalues()(0), 0.0, 1.0);
}

InertialStatePrior PositionYawPrior(const NavState& state, const ImuBias& bias,
                                    double information) {
  InertialStatePrior prior;
  prior.mean = state;
  prior.bias_mean = bias;
  // The residual's position part is R_0^T (p - p_0): isotropic information is the same in any
  // frame. Its rotation part phi is in the body frame; the yaw is e_z . (R_0 phi) = u . phi.
  // The root is set exactly: rows 0-2 hold the position, row 3 the yaw, the rest are zero.
  const double w = std::sqrt(information);
  const Eigen::Vector3d u = state.world_from_body.so3().Inverse() * Eigen::Vector3d::UnitZ();
  Eigen::Matrix<double, 15, 15> root = Eigen::Matrix<double, 15, 15>::Zero();
  root.block<3, 3>(0, 0) = w * Eigen::Matrix3d::Identity();
  root.block<1, 3>(3, 3) = w * u.transpose();
  prior.sqrt_information = root;
  prior.information = root.transpose() * root;
  return prior;
}

}  // namespace pkslam
