// IMU data carried by frames and keyframes: raw measurements, biases, the sensor's noise model
// and the state of an on-manifold preintegration (Forster et al., TRO 2017). Value types only;
// the algorithms that fill and use them (integration, bias correction, factors, initialisation)
// live in imu/ (library pkslam_imu), which sits above core.
//
// Frames: every quantity is in the body (IMU) frame b unless its name says otherwise. The
// preintegration of an interval [t_i, t_j] expresses the motion of body frame j in body frame i
// with gravity removed:
//   delta_R = R_wb_i^T R_wb_j
//   delta_v = R_wb_i^T (v_j - v_i - g_w dt)
//   delta_p = R_wb_i^T (p_j - p_i - v_i dt - g_w dt^2 / 2)
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/geometry/se3.h"
#include "core/geometry/so3.h"

namespace pkslam {

// One IMU reading, in the IMU (body) frame.
struct ImuMeasurement {
  std::int64_t t_ns = 0;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();   // angular velocity [rad/s]
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  // specific force [m/s^2]
};

// Gyroscope and accelerometer biases: measurement = truth + bias + noise.
struct ImuBias {
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();   // [rad/s]
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  // [m/s^2]

  ImuBias() = default;
  ImuBias(const Eigen::Vector3d& gyro_bias, const Eigen::Vector3d& accel_bias)
      : gyro(gyro_bias), accel(accel_bias) {}
  // [gyro; accel], the order of the preintegration covariance's bias blocks.
  Eigen::Matrix<double, 6, 1> Vector() const;
  friend ImuBias operator-(const ImuBias& a, const ImuBias& b) {
    return {a.gyro - b.gyro, a.accel - b.accel};
  }
  friend ImuBias operator+(const ImuBias& a, const ImuBias& b) {
    return {a.gyro + b.gyro, a.accel + b.accel};
  }
  bool operator==(const ImuBias& other) const = default;
};

// Noise model of the IMU: continuous-time densities (as in EuRoC's sensor.yaml / Kalibr and
// ORB-SLAM3's IMU.Noise* settings) and the sample rate. This is the whole IMU calibration the
// preintegration needs; the body-to-camera extrinsics live in CameraRig.
struct ImuNoise {
  double gyro_noise_density = 1.7e-4;   // sigma_g  [rad/s/sqrt(Hz)]
  double accel_noise_density = 2.0e-3;  // sigma_a  [m/s^2/sqrt(Hz)]
  double gyro_random_walk = 1.9393e-5;  // sigma_bg [rad/s^2/sqrt(Hz)]
  double accel_random_walk = 3.0e-3;    // sigma_ba [m/s^3/sqrt(Hz)]
  double rate_hz = 200.0;               // sample rate f (sample period 1/f)

  // Throws OptionError unless every field is positive and finite.
  void Check() const;
};

// Continuous-to-discrete conversion (documented once here, used by the preintegration):
// - White measurement noise: a sample averages the signal over one sample period 1/f, so its
//   noise has variance sigma^2 * f, i.e. sigma_d = sigma_c / sqrt(1/f) = sigma_c * sqrt(f)
//   (ORB-SLAM3 multiplies the densities by sqrt(f)). It is a property of the sample, so it does
//   not change when an integration step is shorter than a period (frame-boundary pieces).
// - Bias random walk: over an interval dt the bias moves with variance sigma^2 * dt, i.e.
//   sigma_d = sigma_c * sqrt(dt) (ORB-SLAM3 divides by sqrt(f) and adds it once per step, which
//   equals this when dt = 1/f; we use the actual dt so partial steps do not over-count).

// diag(sigma_g^2 f (x3), sigma_a^2 f (x3)): covariance of one sample's [gyro; accel] noise.
Eigen::Matrix<double, 6, 6> DiscreteMeasurementCovariance(const ImuNoise& noise);
// diag(sigma_bg^2 dt (x3), sigma_ba^2 dt (x3)): covariance of the bias change over dt seconds.
Eigen::Matrix<double, 6, 6> BiasRandomWalkCovariance(const ImuNoise& noise, double dt);

// How one preintegration step rotates the specific force (see imu/preintegration.h). Both
// integrate the mean of the step's two end samples.
enum class ImuIntegrationScheme {
  // Rotation at the middle of the step, dR Exp(w dt / 2): second order in the sample period.
  kMidpoint,
  // Rotation at the start of the step, dR (ORB-SLAM3's IMU::Preintegrated): first order.
  kOrbSlam3,
};

// Body position, orientation and velocity (a navigation state) at one instant.
struct NavState {
  SE3d world_from_body;
  Eigen::Vector3d velocity_world = Eigen::Vector3d::Zero();  // [m/s]
};

// State of the preintegration of IMU measurements over one interval (between two frames or
// keyframes). Filled by imu/preintegration.h; a plain value, copied with the frame that owns
// it. Error-state ordering of `covariance` (and of the residuals built from it):
//   [dphi (0..2), dv (3..5), dp (6..8), d bias_gyro (9..11), d bias_accel (12..14)]
// where delta_R_true = delta_R * Exp(dphi) and the bias blocks hold the random walk over dt.
struct PreintegratedImu {
  // One integration step as it was fed: bias-uncorrected means over the step and its length.
  struct Step {
    Eigen::Vector3d accel = Eigen::Vector3d::Zero();  // [m/s^2]
    Eigen::Vector3d gyro = Eigen::Vector3d::Zero();   // [rad/s]
    double dt = 0;                                    // [s]
  };

  double dt = 0;  // integrated time [s] (dT)
  SO3d delta_R;
  Eigen::Vector3d delta_v = Eigen::Vector3d::Zero();
  Eigen::Vector3d delta_p = Eigen::Vector3d::Zero();
  // First-order bias Jacobians at `bias` (d delta / d bias), for correction without
  // re-integration: delta_R(b) = delta_R Exp(J_R_bg (b_g - bias.gyro)), etc.
  Eigen::Matrix3d J_R_bg = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d J_v_bg = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d J_v_ba = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d J_p_bg = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d J_p_ba = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 15, 15> covariance = Eigen::Matrix<double, 15, 15>::Zero();
  // The bias the deltas were integrated with (the linearisation point).
  ImuBias bias;
  // Noise model used for `covariance` and the scheme (kept so re-integration and merging
  // reproduce the same computation).
  ImuNoise noise;
  ImuIntegrationScheme scheme = ImuIntegrationScheme::kMidpoint;
  // Time-weighted means over the interval: bias-corrected specific force rotated into the body
  // frame at the start of the interval, and bias-corrected angular velocity.
  Eigen::Vector3d average_accel = Eigen::Vector3d::Zero();
  Eigen::Vector3d average_gyro = Eigen::Vector3d::Zero();
  // Every step integrated so far, for re-integration at a new bias and for merging.
  std::vector<Step> steps;
};

}  // namespace pkslam
