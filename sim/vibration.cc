#include "sim/vibration.h"

#include <cmath>
#include <numbers>

#include "core/geometry/so3.h"
#include "core/util/error.h"
#include "sim/random.h"

namespace pkslam::sim {

std::array<double, 6> VibrationSpectrum::Rms() const {
  std::array<double, 6> power{};
  for (const Bin& b : bins) {
    for (int a = 0; a < 6; ++a) power[a] += b.psd[a] * (b.f_hi_hz - b.f_lo_hz);
  }
  for (double& p : power) p = std::sqrt(p);
  return power;
}

void VibrationSpectrum::Check() const {
  double previous_hi = 0.0;
  for (const Bin& b : bins) {
    PKSLAM_CHECK_OPTION(b.f_lo_hz >= previous_hi && b.f_hi_hz > b.f_lo_hz, "vibration spectrum",
                        "bin [{}, {}] Hz overlaps or is empty", b.f_lo_hz, b.f_hi_hz);
    for (double p : b.psd) {
      PKSLAM_CHECK_OPTION(std::isfinite(p) && p >= 0.0, "vibration spectrum", "PSD {}", p);
    }
    previous_hi = b.f_hi_hz;
  }
}

void VibrationOptions::Check() const {
  PKSLAM_CHECK_OPTION(scale >= 0.0 && scale <= 10.0, "vibration.scale", "{}", scale);
  PKSLAM_CHECK_OPTION(tones_per_bin >= 1 && tones_per_bin <= 64, "vibration.tones_per_bin", "{}",
                      tones_per_bin);
}

Vibration::Vibration(const VibrationSpectrum& spectrum, const VibrationOptions& options,
                     std::uint64_t seed) {
  spectrum.Check();
  options.Check();
  Rng rng(DeriveSeed(seed, 0x5649425241));  // "VIBRA"
  for (const auto& bin : spectrum.bins) {
    const double width = bin.f_hi_hz - bin.f_lo_hz;
    for (int axis = 0; axis < 6; ++axis) {
      // n tones of amplitude A carry n A^2 / 2 = PSD * width.
      const double amplitude =
          options.scale * std::sqrt(2.0 * bin.psd[axis] * width / options.tones_per_bin);
      for (int k = 0; k < options.tones_per_bin; ++k) {
        Tone t;
        t.omega = 2.0 * std::numbers::pi * rng.Uniform(bin.f_lo_hz, bin.f_hi_hz);
        t.phase = rng.Uniform(0.0, 2.0 * std::numbers::pi);
        t.amplitude = amplitude;
        t.axis = axis;
        if (amplitude > 0.0 && t.omega > 0.0) tones_.push_back(t);
      }
    }
  }
}

Vibration::Sample Vibration::At(double t_s) const {
  Sample s;
  for (const Tone& t : tones_) {
    const double angle = t.omega * t_s + t.phase;
    const double sin_a = std::sin(angle);
    const double cos_a = std::cos(angle);
    if (t.axis < 3) {
      // Acceleration A sin(wt + phi) <- displacement -A/w^2 sin(wt + phi).
      const double a = t.amplitude;
      s.d2[t.axis] += a * sin_a;
      s.d1[t.axis] -= a / t.omega * cos_a;
      s.d[t.axis] -= a / (t.omega * t.omega) * sin_a;
    } else {
      // Angular rate B sin(wt + phi) <- angle -B/w cos(wt + phi).
      const double b = t.amplitude;
      const int k = t.axis - 3;
      s.theta1[k] += b * sin_a;
      s.theta[k] -= b / t.omega * cos_a;
      s.theta2[k] += b * t.omega * cos_a;
    }
  }
  return s;
}

BodyState PerturbState(const BodyState& nominal, const Vibration::Sample& v) {
  BodyState out = nominal;
  const SO3d r_n = nominal.world_from_body.so3();
  const Eigen::Vector3d& w = nominal.omega_body;
  const Eigen::Vector3d& alpha = nominal.alpha_body;
  const SO3d delta = SO3d::Exp(v.theta);
  out.world_from_body = SE3d(r_n * delta, nominal.world_from_body.translation() + r_n * v.d);
  out.velocity_world = nominal.velocity_world + r_n * (w.cross(v.d) + v.d1);
  out.acceleration_world =
      nominal.acceleration_world +
      r_n * (v.d2 + 2.0 * w.cross(v.d1) + alpha.cross(v.d) + w.cross(w.cross(v.d)));
  const Eigen::Matrix3d jr = SO3d::RightJacobian(v.theta);
  const Eigen::Vector3d w_rel = jr * v.theta1;
  const Eigen::Vector3d w_nominal_in_body = delta.Inverse() * w;
  out.omega_body = w_nominal_in_body + w_rel;
  out.alpha_body = delta.Inverse() * alpha + w_nominal_in_body.cross(w_rel) + jr * v.theta2;
  return out;
}

}  // namespace pkslam::sim
