// IMU measurements from the motion's analytic derivatives:
//   f     = R_wb^T (a_w - g_w)                                  (true specific force)
//   gyro  = M_g omega_body + G f + b_g + n_g,   accel = M_a f + b_a + n_a  (+ tones)
// with discrete white noise sigma_c / sqrt(dt) and bias random walks sigma_c * sqrt(dt) per
// sample (continuous-time densities as in Kalibr/EuRoC sensor.yaml). g_w = (0, 0, -gravity).
// M_g, M_a (scale factors and axis misalignment) and G (gyro g-sensitivity) are the
// deterministic sensor errors of ImuSensorErrors (identity / zero by default).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "sim/body_motion.h"

namespace pkslam::sim {

// Deterministic errors a factory-calibrated MEMS IMU keeps (see sim/realism.h for their sizes).
struct ImuSensorErrors {
  Eigen::Matrix3d gyro_matrix = Eigen::Matrix3d::Identity();     // scale factor + misalignment
  Eigen::Matrix3d accel_matrix = Eigen::Matrix3d::Identity();    // scale factor + misalignment
  Eigen::Matrix3d gyro_g_sensitivity = Eigen::Matrix3d::Zero();  // rad/s per m/s^2
  double gyro_quantum = 0.0;   // output resolution, rad/s (0: none); applied last
  double accel_quantum = 0.0;  // output resolution, m/s^2 (0: none)

  bool IsIdeal() const;
};

struct ImuOptions {
  double rate_hz = 200.0;                 // sample rate; 1e9/rate_hz must be an integer ns
  double gyro_noise_density = 1.6968e-4;  // rad/s/sqrt(Hz) (EuRoC ADIS16448)
  double gyro_random_walk = 1.9393e-5;    // rad/s^2/sqrt(Hz)
  double accel_noise_density = 2.0e-3;    // m/s^2/sqrt(Hz)
  double accel_random_walk = 3.0e-3;      // m/s^3/sqrt(Hz)
  Eigen::Vector3d initial_gyro_bias = Eigen::Vector3d::Zero();   // rad/s
  Eigen::Vector3d initial_accel_bias = Eigen::Vector3d::Zero();  // m/s^2
  bool noise = true;       // false: exact measurements, biases stay at their initial values
  ImuSensorErrors errors;  // scale factors, misalignment, g-sensitivity
  bool vibration = false;  // add rotor vibration tones (35-90 Hz) to the measurements only
  double vibration_accel_rms = 0.3;  // m/s^2, total RMS over axes of the accel tones
  double vibration_gyro_rms = 0.01;  // rad/s, total RMS of the gyro tones
  int vibration_tones = 4;           // number of sinusoids
  double gravity = 9.81;             // m/s^2 along world -z

  std::int64_t period_ns() const;
  void Check() const;
};

struct ImuSample {
  std::int64_t t_ns = 0;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();        // rad/s, body frame
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();       // m/s^2, body frame
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();   // true bias in this sample
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();  // true bias in this sample
};

// Exact (noise-free, bias-free) gyro and accelerometer values of a body state.
void IdealImu(const BodyState& state, double gravity, Eigen::Vector3d* gyro,
              Eigen::Vector3d* accel);

// Samples at t = begin_ns + k * period for t <= end_ns; deterministic in `seed`.
std::vector<ImuSample> SimulateImu(const BodyMotion& motion, std::int64_t begin_ns,
                                   std::int64_t end_ns, const ImuOptions& options,
                                   std::uint64_t seed);

}  // namespace pkslam::sim
