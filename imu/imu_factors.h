// Ceres cost functions of inertial problems, with analytic Jacobians (checked against numeric
// differentiation in imu_factors_test.cc). Parameter blocks and manifolds: imu/imu_manifolds.h
// (world_from_body pose blocks with a right perturbation, Euclidean velocity / bias / log-scale
// blocks, a 2-DoF gravity-direction block). Pose-block Jacobians follow the [I6; 0] convention.
//
// The inertial residual between body states i and j (ORB-SLAM3's EdgeInertial), with the
// preintegration's deltas corrected to first order at the bias b_i of state i:
//   r_R = Log(dR(b_i)^T R_i^T R_j)
//   r_v = R_i^T (v_j - v_i - g dt) - dv(b_i)
//   r_p = R_i^T (p_j - p_i - v_i dt - g dt^2 / 2) - dp(b_i)
// stacked [r_R; r_v; r_p] and whitened by the preintegration's square-root information.
// All residuals here are whitened: |r|^2 is a chi2 value.
#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <memory>

#include "core/geometry/se3.h"
#include "core/imu/imu_types.h"
#include "imu/preintegration.h"

namespace pkslam {

// Unwhitened [r_R; r_v; r_p] of the inertial residual (for diagnostics and tests).
Eigen::Matrix<double, 9, 1> InertialResidual(const PreintegratedImu& pim,
                                             const Eigen::Vector3d& gravity_world,
                                             const NavState& state_i, const ImuBias& bias_i,
                                             const NavState& state_j);

// Inertial edge. Parameters {pose_i[7], v_i[3], bias_gyro_i[3], bias_accel_i[3], pose_j[7],
// v_j[3]}; residual 9. `gravity_world` is g in the world frame of the poses.
class InertialError final : public ceres::SizedCostFunction<9, 7, 3, 3, 3, 7, 3> {
 public:
  InertialError(const PreintegratedImu& pim, const Eigen::Vector3d& gravity_world);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  const Eigen::Matrix<double, 9, 9>& sqrt_information() const { return sqrt_info_; }

 private:
  PreintegratedImu pim_;  // without its steps
  Eigen::Vector3d gravity_world_;
  Eigen::Matrix<double, 9, 9> sqrt_info_;
};

// The inertial edge with the IMU's axis errors as parameters (online calibration,
// docs/calibration.md): the gyroscope's per-axis scale-factor error k (it reads (1 + k) times the
// true rate) and the accelerometer's axis errors E (it reads (I + E) times the true specific
// force; row-major 9-vector). pim's steps were corrected with `integrated_gyro_scale` (divided by
// 1 + k_integrated) and `integrated_accel_axes` (multiplied by (I + E_integrated)^-1); the deltas
// follow k and E to first order through GyroScaleJacobiansOf and AccelAxesJacobiansOf
// (imu/preintegration.h), then the residual is InertialError's. A block the solve holds is set
// constant: at its integrated value its shift is exactly zero.
// Parameters {pose_i[7], v_i[3], bias_gyro_i[3], bias_accel_i[3], pose_j[7], v_j[3], k[3],
// E[9]}; residual 9.
class ImuAxesInertialError final : public ceres::SizedCostFunction<9, 7, 3, 3, 3, 7, 3, 3, 9> {
 public:
  // The Jacobians of pim, computed where pim still has its steps.
  ImuAxesInertialError(const PreintegratedImu& pim, const Eigen::Vector3d& gravity_world,
                       const GyroScaleJacobians& gyro, const AccelAxesJacobians& accel,
                       const Eigen::Vector3d& integrated_gyro_scale,
                       const Eigen::Matrix3d& integrated_accel_axes);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  PreintegratedImu pim_;  // without its steps
  Eigen::Vector3d gravity_world_;
  Eigen::Matrix<double, 9, 9> sqrt_info_;
  GyroScaleJacobians gyro_;
  AccelAxesJacobians accel_;
  Eigen::Vector3d inv_integrated_;  // 1 / (1 + integrated_gyro_scale), per axis
  Eigen::Vector3d integrated_scale_;
  Eigen::Matrix<double, 9, 1> integrated_axes_;  // row-major, as the parameter block
  // d vec(dE') / d vec(E) = (I + E_integrated)^-1 kron I3 (row-major vectors).
  Eigen::Matrix<double, 9, 9> axes_to_corrected_;
};

// Bias random walk between consecutive bias blocks: r = W (b_j - b_i), W^T W = covariance^-1.
// Parameters {b_i[3], b_j[3]}; residual 3.
class BiasRandomWalkError final : public ceres::SizedCostFunction<3, 3, 3> {
 public:
  explicit BiasRandomWalkError(const Eigen::Matrix3d& covariance);
  // The gyro (accel) walk over pim's interval: covariance block 9..11 (12..14).
  static std::unique_ptr<BiasRandomWalkError> Gyro(const PreintegratedImu& pim);
  static std::unique_ptr<BiasRandomWalkError> Accel(const PreintegratedImu& pim);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Matrix3d sqrt_info_;
};

// Inertial-only initialisation edge (ORB-SLAM3's EdgeInertialGS): the poses are fixed, known
// up to scale (monocular), in a world frame whose gravity direction is unknown. With
// s = exp(log_scale) and g = R_wg (0, 0, -gravity_magnitude):
//   r_R = Log(dR(b)^T R_i^T R_j)
//   r_v = R_i^T (s (v_j - v_i) - g dt) - dv(b)
//   r_p = R_i^T (s (p_j - p_i - v_i dt) - g dt^2 / 2) - dp(b)
// Velocities are in the poses' (unscaled) units: the metric velocity is s * v.
// Parameters {v_i[3], v_j[3], bias_gyro[3], bias_accel[3], R_wg[4] (GravityDirectionManifold),
// log_scale[1]}; residual 9. The R_wg Jacobian is [d r / d delta (2 columns), 0, 0].
class InertialGravityScaleError final : public ceres::SizedCostFunction<9, 3, 3, 3, 3, 4, 1> {
 public:
  InertialGravityScaleError(const PreintegratedImu& pim, const SE3d& world_from_body_i,
                            const SE3d& world_from_body_j, double gravity_magnitude);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  PreintegratedImu pim_;  // without its steps
  SE3d world_from_body_i_;
  SE3d world_from_body_j_;
  double gravity_magnitude_;
  Eigen::Matrix<double, 9, 9> sqrt_info_;
};

// Prior on a bias block: r = W (b - prior). Parameters {b[3]}; residual 3.
class BiasPriorError final : public ceres::SizedCostFunction<3, 3> {
 public:
  BiasPriorError(const Eigen::Vector3d& prior, const Eigen::Matrix3d& sqrt_information)
      : prior_(prior), sqrt_info_(sqrt_information) {}
  // Isotropic: information = `information` * I (ORB-SLAM3's priorG / priorA).
  BiasPriorError(const Eigen::Vector3d& prior, double information);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector3d prior_;
  Eigen::Matrix3d sqrt_info_;
};

// Prior on a whole inertial state (marginalisation-like, ORB-SLAM3's EdgePriorPoseImu), in the
// tangent coordinates of the blocks at the prior:
//   r = W [R_0^T (p - p_0); Log(R_0^T R); v - v_0; b_g - b_g0; b_a - b_a0]
// (the pose part in the [rho; phi] order of BodyPoseManifold). `information` is 15 x 15 in that
// order (zero rows/columns leave a part free). Parameters {pose[7], v[3], b_g[3], b_a[3]}.
class InertialStatePriorError final : public ceres::SizedCostFunction<15, 7, 3, 3, 3> {
 public:
  InertialStatePriorError(const NavState& prior_state, const ImuBias& prior_bias,
                          const Eigen::Matrix<double, 15, 15>& information);
  // With a given square root W of the information (r = W [...]), e.g. for a rank-deficient
  // prior whose root is known exactly.
  struct SqrtInformation {};
  InertialStatePriorError(const NavState& prior_state, const ImuBias& prior_bias,
                          const Eigen::Matrix<double, 15, 15>& sqrt_information, SqrtInformation);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  NavState prior_state_;
  ImuBias prior_bias_;
  Eigen::Matrix<double, 15, 15> sqrt_info_;
};

}  // namespace pkslam
