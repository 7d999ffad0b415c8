// Helpers for Lie-group property tests: random tangents and numeric right Jacobians.
#pragma once

#include <random>

#include <Eigen/Core>

namespace pkslam::testing {

template <int N>
Eigen::Matrix<double, N, 1> RandomTangent(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::Matrix<double, N, 1> v;
  for (int i = 0; i < N; ++i) v(i) = u(rng);
  return v;
}

// Numeric right Jacobian of Exp at x: column i = Log(Exp(x)^-1 Exp(x + h e_i)) / h (central).
template <typename Group>
Eigen::Matrix<double, Group::kDof, Group::kDof> NumericRightJacobian(
    const typename Group::Tangent& x) {
  constexpr int n = Group::kDof;
  constexpr double h = 1e-6;
  Eigen::Matrix<double, n, n> j;
  const Group inv = Group::Exp(x).Inverse();
  for (int i = 0; i < n; ++i) {
    typename Group::Tangent d = Group::Tangent::Zero();
    d(i) = h;
    j.col(i) = ((inv * Group::Exp(x + d)).Log() - (inv * Group::Exp(x - d)).Log()) / (2 * h);
  }
  return j;
}

}  // namespace pkslam::testing
