// Test-only helpers for imu/: an analytic body motion with exact IMU measurements, sampled
// (optionally noisy) IMU streams, and numeric Jacobians of Ceres cost functions on manifolds.
#pragma once

#include <ceres/cost_function.h>
#include <ceres/manifold.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/geometry/se3.h"
#include "core/imu/imu_types.h"

namespace pkslam::testing {

// A body on a helix-like path (radius 2 m, climbing and bobbing) with a smoothly varying
// orientation R(t) = Exp(theta(t)), |theta| < 1.3 rad. Derivatives are analytic, so the IMU
// values are exact: gyro = Jr(theta) theta', accel = R^T (p'' - g).
class HelixMotion {
 public:
  explicit HelixMotion(double speed = 1.0) : w_(0.8 * speed) {}

  Eigen::Vector3d Position(double t) const {
    return {2.0 * std::cos(w_ * t), 2.0 * std::sin(w_ * t), 0.2 * t + 0.3 * std::sin(1.7 * t)};
  }
  Eigen::Vector3d Velocity(double t) const {
    return {-2.0 * w_ * std::sin(w_ * t), 2.0 * w_ * std::cos(w_ * t),
            0.2 + 0.51 * std::cos(1.7 * t)};
  }
  Eigen::Vector3d Acceleration(double t) const {
    return {-2.0 * w_ * w_ * std::cos(w_ * t), -2.0 * w_ * w_ * std::sin(w_ * t),
            -0.867 * std::sin(1.7 * t)};
  }
  Eigen::Vector3d Theta(double t) const {
    return {0.4 * std::sin(1.1 * t), 0.3 * std::sin(0.9 * t + 1.0), 1.2 * std::sin(0.5 * t)};
  }
  Eigen::Vector3d ThetaDot(double t) const {
    return {0.44 * std::cos(1.1 * t), 0.27 * std::cos(0.9 * t + 1.0), 0.6 * std::cos(0.5 * t)};
  }
  SO3d Rotation(double t) const { return SO3d::Exp(Theta(t)); }
  NavState State(double t) const { return {SE3d(Rotation(t), Position(t)), Velocity(t)}; }
  Eigen::Vector3d Gyro(double t) const { return SO3d::RightJacobian(Theta(t)) * ThetaDot(t); }
  Eigen::Vector3d Accel(double t, const Eigen::Vector3d& gravity_world) const {
    return Rotation(t).Inverse() * (Acceleration(t) - gravity_world);
  }

 private:
  double w_;
};

inline const Eigen::Vector3d kTestGravity(0, 0, -9.81);

inline double Seconds(std::int64_t t_ns) { return static_cast<double>(t_ns) * 1e-9; }

// IMU samples of `motion` at t0 + k * period for t <= t1 (ns), with constant bias `bias` and,
// if rng is not null, white noise of the discrete sigma of `noise` (sigma_c * sqrt(1/period)).
template <typename Motion>
std::vector<ImuMeasurement> SampleImu(const Motion& motion, std::int64_t t0_ns, std::int64_t t1_ns,
                                      std::int64_t period_ns, const ImuBias& bias,
                                      const ImuNoise& noise, std::mt19937* rng,
                                      const Eigen::Vector3d& gravity = kTestGravity) {
  std::normal_distribution<double> n01(0.0, 1.0);
  const double rate = 1e9 / static_cast<double>(period_ns);
  const double sg = noise.gyro_noise_density * std::sqrt(rate);
  const double sa = noise.accel_noise_density * std::sqrt(rate);
  std::vector<ImuMeasurement> out;
  for (std::int64_t t = t0_ns; t <= t1_ns; t += period_ns) {
    ImuMeasurement m;
    m.t_ns = t;
    m.gyro = motion.Gyro(Seconds(t)) + bias.gyro;
    m.accel = motion.Accel(Seconds(t), gravity) + bias.accel;
    if (rng != nullptr) {
      for (int i = 0; i < 3; ++i) {
        m.gyro(i) += sg * n01(*rng);
        m.accel(i) += sa * n01(*rng);
      }
    }
    out.push_back(m);
  }
  return out;
}

// Numeric Jacobian (central differences in the tangent space of each block's manifold; null
// manifold = Euclidean) of a cost function, and the analytic one mapped to the tangent space
// (ambient Jacobian times PlusJacobian). Both row-major residuals x tangent.
struct JacobianPair {
  Eigen::MatrixXd analytic;
  Eigen::MatrixXd numeric;
};

inline std::vector<JacobianPair> CompareJacobians(
    const ceres::CostFunction& cost, const std::vector<std::vector<double>>& blocks,
    const std::vector<const ceres::Manifold*>& manifolds, double h = 1e-6) {
  const int m = cost.num_residuals();
  const std::vector<std::int32_t>& sizes = cost.parameter_block_sizes();
  std::vector<const double*> params;
  for (const std::vector<double>& b : blocks) params.push_back(b.data());
  std::vector<std::vector<double>> jac_storage(blocks.size());
  std::vector<double*> jac_ptrs;
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    jac_storage[i].assign(static_cast<std::size_t>(m * sizes[i]), 0.0);
    jac_ptrs.push_back(jac_storage[i].data());
  }
  Eigen::VectorXd r0(m);
  if (!cost.Evaluate(params.data(), r0.data(), jac_ptrs.data())) return {};

  std::vector<JacobianPair> out;
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const int ambient = sizes[i];
    const ceres::Manifold* man = manifolds[i];
    const int tangent = man != nullptr ? man->TangentSize() : ambient;
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>
        ja(jac_storage[i].data(), m, ambient);
    Eigen::MatrixXd plus_jac = Eigen::MatrixXd::Identity(ambient, tangent);
    if (man != nullptr) {
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> pj(ambient, tangent);
      man->PlusJacobian(blocks[i].data(), pj.data());
      plus_jac = pj;
    }
    JacobianPair pair;
    pair.analytic = ja * plus_jac;
    pair.numeric.resize(m, tangent);
    for (int c = 0; c < tangent; ++c) {
      Eigen::VectorXd r_plus(m), r_minus(m);
      for (const double sign : {1.0, -1.0}) {
        std::vector<double> moved(static_cast<std::size_t>(ambient));
        Eigen::VectorXd delta = Eigen::VectorXd::Zero(tangent);
        delta(c) = sign * h;
        if (man != nullptr) {
          man->Plus(blocks[i].data(), delta.data(), moved.data());
        } else {
          for (int k = 0; k < ambient; ++k) moved[k] = blocks[i][k] + delta(k);
        }
        std::vector<const double*> p = params;
        p[i] = moved.data();
        cost.Evaluate(p.data(), sign > 0 ? r_plus.data() : r_minus.data(), nullptr);
      }
      pair.numeric.col(c) = (r_plus - r_minus) / (2 * h);
    }
    out.push_back(pair);
  }
  return out;
}

}  // namespace pkslam::testing
