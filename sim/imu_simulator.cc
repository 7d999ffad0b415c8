#include "sim/imu_simulator.h"

#include <cmath>
#include <numbers>

#include "core/util/error.h"
#include "sim/random.h"

namespace pkslam::sim {

std::int64_t ImuOptions::period_ns() const {
  return static_cast<std::int64_t>(std::llround(1e9 / rate_hz));
}

bool ImuSensorErrors::IsIdeal() const {
  return gyro_matrix.isIdentity(0.0) && accel_matrix.isIdentity(0.0) &&
         gyro_g_sensitivity.isZero(0.0) && gyro_quantum == 0.0 && accel_quantum == 0.0;
}

void ImuOptions::Check() const {
  PKSLAM_CHECK_OPTION(rate_hz >= 10.0 && rate_hz <= 10000.0, "imu.rate_hz", "{}", rate_hz);
  PKSLAM_CHECK_OPTION(std::abs(1e9 / rate_hz - static_cast<double>(period_ns())) < 1e-6,
                      "imu.rate_hz", "period {} ns is not an integer", 1e9 / rate_hz);
  PKSLAM_CHECK_OPTION(gyro_noise_density >= 0 && gyro_random_walk >= 0 &&
                          accel_noise_density >= 0 && accel_random_walk >= 0,
                      "imu noise", "densities must be >= 0");
  PKSLAM_CHECK_OPTION(initial_gyro_bias.allFinite() && initial_accel_bias.allFinite(), "imu bias",
                      "must be finite");
  PKSLAM_CHECK_OPTION(vibration_accel_rms >= 0 && vibration_gyro_rms >= 0, "vibration",
                      "rms must be >= 0");
  PKSLAM_CHECK_OPTION(vibration_tones >= 1 && vibration_tones <= 64, "vibration_tones", "{}",
                      vibration_tones);
  PKSLAM_CHECK_OPTION(gravity > 0.0, "gravity", "{}", gravity);
  PKSLAM_CHECK_OPTION(errors.gyro_matrix.allFinite() && errors.accel_matrix.allFinite() &&
                          errors.gyro_g_sensitivity.allFinite(),
                      "imu errors", "{}", "must be finite");
  PKSLAM_CHECK_OPTION(
      (errors.gyro_matrix - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 0.2 &&
          (errors.accel_matrix - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 0.2,
      "imu errors", "{}", "scale/misalignment entries must stay within 0.2 of identity");
}

void IdealImu(const BodyState& state, double gravity, Eigen::Vector3d* gyro,
              Eigen::Vector3d* accel) {
  const Eigen::Vector3d g_world(0.0, 0.0, -gravity);
  *gyro = state.omega_body;
  *accel = state.world_from_body.so3().Inverse() * (state.acceleration_world - g_world);
}

namespace {

// A sum of sinusoids with random frequency, phase and direction: the rotor vibration of a
// multicopter seen by its IMU (no effect on the rendered camera: amplitudes are micrometres).
struct Tone {
  double frequency_hz;
  double phase;
  Eigen::Vector3d amplitude;  // per-axis amplitude (direction * magnitude)
};

std::vector<Tone> MakeTones(Rng* rng, int count, double rms) {
  std::vector<Tone> tones;
  // Equal amplitudes A with total RMS sqrt(count * A^2 / 2) = rms.
  const double amplitude = rms * std::sqrt(2.0 / count);
  for (int i = 0; i < count; ++i) {
    Tone t;
    t.frequency_hz = rng->Uniform(35.0, 90.0);
    t.phase = rng->Uniform(0.0, 2.0 * std::numbers::pi);
    // One draw per statement: argument evaluation order is unspecified in C++.
    Eigen::Vector3d dir;
    for (int k = 0; k < 3; ++k) dir[k] = rng->Normal();
    t.amplitude = amplitude * dir.normalized();
    tones.push_back(t);
  }
  return tones;
}

Eigen::Vector3d EvaluateTones(const std::vector<Tone>& tones, double t_s) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Tone& t : tones) {
    sum += std::sin(2.0 * std::numbers::pi * t.frequency_hz * t_s + t.phase) * t.amplitude;
  }
  return sum;
}

// The sensor's output resolution: round to whole LSBs.
Eigen::Vector3d Quantise(const Eigen::Vector3d& v, double quantum) {
  return (v / quantum).array().round().matrix() * quantum;
}

}  // namespace

std::vector<ImuSample> SimulateImu(const BodyMotion& motion, std::int64_t begin_ns,
                                   std::int64_t end_ns, const ImuOptions& options,
                                   std::uint64_t seed) {
  options.Check();
  PKSLAM_CHECK(begin_ns >= motion.begin_ns() && end_ns <= motion.end_ns(),
               "IMU window [{}, {}] outside the trajectory [{}, {}]", begin_ns, end_ns,
               motion.begin_ns(), motion.end_ns());
  const std::int64_t period = options.period_ns();
  const double dt = 1e-9 * static_cast<double>(period);
  const double gyro_sigma = options.gyro_noise_density / std::sqrt(dt);
  const double accel_sigma = options.accel_noise_density / std::sqrt(dt);
  const double gyro_walk = options.gyro_random_walk * std::sqrt(dt);
  const double accel_walk = options.accel_random_walk * std::sqrt(dt);

  Rng noise_rng(DeriveSeed(seed, 0x494D55));  // "IMU"
  Rng tone_rng(DeriveSeed(seed, 0x564942));   // "VIB"
  std::vector<Tone> accel_tones;
  std::vector<Tone> gyro_tones;
  if (options.vibration) {
    accel_tones = MakeTones(&tone_rng, options.vibration_tones, options.vibration_accel_rms);
    gyro_tones = MakeTones(&tone_rng, options.vibration_tones, options.vibration_gyro_rms);
  }

  const bool ideal_sensor = options.errors.IsIdeal();
  std::vector<ImuSample> out;
  out.reserve(static_cast<std::size_t>((end_ns - begin_ns) / period + 1));
  Eigen::Vector3d bg = options.initial_gyro_bias;
  Eigen::Vector3d ba = options.initial_accel_bias;
  auto normal3 = [&noise_rng]() {
    const double x = noise_rng.Normal();
    const double y = noise_rng.Normal();
    const double z = noise_rng.Normal();
    return Eigen::Vector3d(x, y, z);
  };
  for (std::int64_t t = begin_ns; t <= end_ns; t += period) {
    ImuSample s;
    s.t_ns = t;
    IdealImu(motion.State(t), options.gravity, &s.gyro, &s.accel);
    if (!ideal_sensor) {
      s.gyro = options.errors.gyro_matrix * s.gyro + options.errors.gyro_g_sensitivity * s.accel;
      s.accel = options.errors.accel_matrix * s.accel;
    }
    s.gyro_bias = bg;
    s.accel_bias = ba;
    s.gyro += bg;
    s.accel += ba;
    if (options.vibration) {
      const double ts = 1e-9 * static_cast<double>(t - begin_ns);
      s.accel += EvaluateTones(accel_tones, ts);
      s.gyro += EvaluateTones(gyro_tones, ts);
    }
    if (options.noise) {
      // Fixed draw order (gyro noise, accel noise, gyro walk, accel walk) fixes the bytes.
      s.gyro += gyro_sigma * normal3();
      s.accel += accel_sigma * normal3();
      bg += gyro_walk * normal3();
      ba += accel_walk * normal3();
    }
    if (options.errors.gyro_quantum > 0.0) s.gyro = Quantise(s.gyro, options.errors.gyro_quantum);
    if (options.errors.accel_quantum > 0.0) {
      s.accel = Quantise(s.accel, options.errors.accel_quantum);
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace pkslam::sim
