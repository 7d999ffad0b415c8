// On-manifold IMU preintegration (Forster, Carlone, Dellaert, Scaramuzza, TRO 2017), as
// ORB-SLAM3's IMU::Preintegrated: deltas, first-order bias Jacobians and the covariance of
// the deltas, operating on the value type PreintegratedImu (core/imu/imu_types.h).
//
// Integration scheme. Each step integrates one interval between two consecutive samples with
// the MEAN of the two samples (as ORB-SLAM3), a = accel - b_a, w = gyro - b_g:
//   delta_p += delta_v dt + 1/2 R_s a dt^2
//   delta_v += R_s a dt
//   delta_R  = delta_R Exp(w dt)
// where R_s rotates the step's specific force into the interval's first body frame:
// - kMidpoint (default): R_s = delta_R Exp(w dt / 2), the rotation at the middle of the step,
//   where the mean of the two samples is taken. Second order: the global error shrinks 4x when
//   the sample period halves.
// - kOrbSlam3: R_s = delta_R (start of the step), ORB-SLAM3's IMU::Preintegrated. First order
//   in rotation x specific force: over T seconds it errs by ~ T dt |w x a| / 2 in velocity, e.g.
//   6 mm/s over a 0.25 s keyframe interval at 1 rad/s and 200 Hz (with |a| ~ g), six times the
//   accelerometer noise over that interval; an accel-bias-like error of dt |w x a| / 2.
// Rotation is second order in both.
//
// Noise: see the continuous-to-discrete note in core/imu/imu_types.h. Per step the covariance of
// [dphi, dv, dp] is propagated as A C A^T + B N B^T with N = DiscreteMeasurementCovariance
// (sample noise, sigma_c^2 f), and the bias blocks grow by BiasRandomWalkCovariance(dt).
//
// Bias handling: the accelerometer bias enters the deltas linearly given the rotation, so the
// first-order correction is exact for it; the gyroscope bias is corrected to first order, and
// re-integration (UpdateBias) moves the linearisation point when it has moved far.
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cstdint>
#include <vector>

#include "core/geometry/so3.h"
#include "core/imu/imu_types.h"

namespace pkslam {

struct PreintegrationOptions {
  // UpdateBias re-integrates when the gyro bias differs from the linearisation bias by more
  // than this [rad/s] (ORB-SLAM3's InertialOptimization uses 0.01).
  double reintegrate_gyro_bias_change = 0.01;
  // ... or when the accel bias differs by more than this [m/s^2]. The accel correction is exact
  // for the deltas (only the covariance changes), so the default never triggers on it.
  double reintegrate_accel_bias_change = 1e9;

  void Check() const;
};

// A fresh preintegration (zero interval) linearised at `bias`. Checks `noise`.
PreintegratedImu StartPreintegration(const ImuBias& bias, const ImuNoise& noise,
                                     ImuIntegrationScheme scheme = ImuIntegrationScheme::kMidpoint);

// Integrates one step: `accel` and `gyro` are the (bias-uncorrected) measurement means over the
// step and `dt` > 0 its length in seconds. Appends the step to pim->steps.
void IntegrateMeasurement(const Eigen::Vector3d& accel, const Eigen::Vector3d& gyro, double dt,
                          PreintegratedImu* pim);

// Integrates the samples over [t_begin_ns, t_end_ns] (a frame interval), handling the partial
// intervals at both ends as ORB-SLAM3's Tracking::PreintegrateIMU: every interval between
// consecutive samples is clipped to [t_begin, t_end], the sample values are linearly
// interpolated at the clipped ends, and the step integrates the mean of its two end values.
// Where the samples do not reach t_begin (t_end), the first (last) sample is held constant.
// (Equal to ORB-SLAM3's steps when >= 3 samples bracket the interval; with only two, ORB-SLAM3
// integrates the first sample alone over the whole interval, and here their interpolation.)
// `samples` must be time-ordered and non-empty (typically: the last sample at or before
// t_begin through the first sample at or after t_end); t_end_ns > t_begin_ns. Throws Error
// otherwise. Returns the number of steps integrated.
int IntegrateSamples(const std::vector<ImuMeasurement>& samples, std::int64_t t_begin_ns,
                     std::int64_t t_end_ns, PreintegratedImu* pim);

// Bias-corrected deltas (first order around pim.bias; exact at bias == pim.bias).
SO3d DeltaRotation(const PreintegratedImu& pim, const ImuBias& bias);
Eigen::Vector3d DeltaVelocity(const PreintegratedImu& pim, const ImuBias& bias);
Eigen::Vector3d DeltaPosition(const PreintegratedImu& pim, const ImuBias& bias);

// First-order Jacobians of the deltas with respect to a change dk of the gyroscope's per-axis
// scale-factor error (the gyro reads (1 + k) times the true rate; online calibration,
// docs/calibration.md): the rates re-scaled by 1 / (1 + k + dk) give, around dk = 0,
//   delta_R Exp(rotation dk),  delta_v + velocity dk,  delta_p + position dk
// (in the steps' frame; replayed from pim.steps at pim.bias, so a pim without steps gives 0).
struct GyroScaleJacobians {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d velocity = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d position = Eigen::Matrix3d::Zero();
};
GyroScaleJacobians GyroScaleJacobiansOf(const PreintegratedImu& pim);

// First-order Jacobians of the deltas with respect to a change dE' of the accelerometer's axis
// errors, expressed in the corrected axes (online calibration, docs/calibration.md: the
// accelerometer reads (I + E) times the true specific force and its samples are corrected with
// (I + E)^-1; moving E to E + dE changes a corrected sample a by -dE' a to first order, with
// dE' = (I + E)^-1 dE). With dE' as a row-major 9-vector, around dE' = 0:
//   delta_v + velocity dE',  delta_p + position dE'  (delta_R does not change)
// (replayed from pim.steps at pim.bias, so a pim without steps gives 0).
struct AccelAxesJacobians {
  Eigen::Matrix<double, 3, 9> velocity = Eigen::Matrix<double, 3, 9>::Zero();
  Eigen::Matrix<double, 3, 9> position = Eigen::Matrix<double, 3, 9>::Zero();
};
AccelAxesJacobians AccelAxesJacobiansOf(const PreintegratedImu& pim);

// Multiplies every step's accelerometer sample and the linearisation bias's accelerometer part
// by `m`, then re-integrates: moves a preintegration from one accelerometer axis correction to
// another (m = (I + E_new)^-1 (I + E_old)). An identity m leaves pim untouched.
void TransformAccel(const Eigen::Matrix3d& m, PreintegratedImu* pim);

// Multiplies every step's gyro sample and the linearisation bias's gyro part by `factor` per
// axis, then re-integrates: moves a preintegration from one gyro scale correction to another
// (factor = (1 + k_old) / (1 + k_new)). A factor of exactly one leaves pim untouched.
void RescaleGyro(const Eigen::Vector3d& factor, PreintegratedImu* pim);

// Re-integrates every stored step at `bias` (it becomes the linearisation point).
void Reintegrate(const ImuBias& bias, PreintegratedImu* pim);

// Moves the linearisation point to `bias` by re-integration when it is farther than the
// options' thresholds from pim->bias; otherwise leaves pim unchanged (the first-order
// correction serves). Returns true if it re-integrated.
bool UpdateBias(const ImuBias& bias, const PreintegrationOptions& options, PreintegratedImu* pim);

// Prepends `previous` (the interval just before pim's) so pim spans both: used when the
// keyframe between them is culled in an inertial map. Re-integrates all steps at pim->bias.
void MergePrevious(const PreintegratedImu& previous, PreintegratedImu* pim);

// The state after pim.dt seconds starting from `start` (at the start of the interval), with
// the bias-corrected deltas and gravity `gravity_world` (e.g. (0, 0, -9.81) in a
// gravity-aligned world):
//   R_j = R_i dR(b),  v_j = v_i + g dt + R_i dv(b),  p_j = p_i + v_i dt + g dt^2/2 + R_i dp(b).
NavState PredictState(const NavState& start, const PreintegratedImu& pim, const ImuBias& bias,
                      const Eigen::Vector3d& gravity_world);

// A square-root information W of a covariance C (W^T W = C^-1, W = D^-1/2 V^T from C = V D
// V^T): residuals are whitened as W r. Eigenvalues below `min_eigenvalue` are raised to it so a
// near-degenerate covariance does not give an infinite weight.
template <int N>
Eigen::Matrix<double, N, N> SqrtInformation(const Eigen::Matrix<double, N, N>& covariance,
                                            double min_eigenvalue = 1e-14) {
  const Eigen::Matrix<double, N, N> sym = 0.5 * (covariance + covariance.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> es(sym);
  const Eigen::Matrix<double, N, 1> inv_sqrt =
      es.eigenvalues().cwiseMax(min_eigenvalue).cwiseSqrt().cwiseInverse();
  return inv_sqrt.asDiagonal() * es.eigenvectors().transpose();
}

// SqrtInformation of the [dphi, dv, dp] block of pim.covariance (the inertial residual's).
Eigen::Matrix<double, 9, 9> PreintegrationSqrtInformation(const PreintegratedImu& pim);

}  // namespace pkslam
