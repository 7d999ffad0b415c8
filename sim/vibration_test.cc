#include "sim/vibration.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/util/error.h"
#include "sim/body_motion.h"
#include "sim/imu_simulator.h"
#include "sim/sim_testing.h"

namespace pkslam::sim {
namespace {

TEST(Vibration, SynthesisHasTheSpectrumsRms) {
  const VibrationSpectrum& spectrum = EurocVibrationSpectrum();
  ASSERT_FALSE(spectrum.bins.empty());
  const std::array<double, 6> rms = spectrum.Rms();
  const Vibration v(spectrum, VibrationOptions{}, 5);
  // Sample 60 s at 1 kHz: the measured quantities (accelerometer = d'', gyro = theta') carry
  // the spectrum's power per axis.
  std::array<double, 6> sum{};
  const int n = 60000;
  for (int i = 0; i < n; ++i) {
    const Vibration::Sample s = v.At(1e-3 * i);
    for (int k = 0; k < 3; ++k) {
      sum[k] += s.d2[k] * s.d2[k];
      sum[3 + k] += s.theta1[k] * s.theta1[k];
    }
  }
  for (int a = 0; a < 6; ++a) {
    EXPECT_NEAR(std::sqrt(sum[a] / n), rms[a], 0.1 * rms[a]) << "axis " << a;
  }
  // The real V1_01 flight: about 1.1 / 0.5 / 0.85 m/s^2 above 6 Hz on the accelerometer.
  EXPECT_GT(rms[0], 0.5);
  EXPECT_LT(rms[0], 2.0);
}

TEST(Vibration, DerivativesMatchNumericDifferentiation) {
  const Vibration v(EurocVibrationSpectrum(), VibrationOptions{}, 9);
  const double h = 1e-6;
  for (double t : {0.1, 1.7, 3.3}) {
    const auto s = v.At(t);
    const auto a = v.At(t - h);
    const auto b = v.At(t + h);
    EXPECT_TRUE(((b.d - a.d) / (2 * h)).isApprox(s.d1, 1e-5));
    EXPECT_TRUE(((b.d1 - a.d1) / (2 * h)).isApprox(s.d2, 1e-5));
    EXPECT_TRUE(((b.theta - a.theta) / (2 * h)).isApprox(s.theta1, 1e-5));
    EXPECT_TRUE(((b.theta1 - a.theta1) / (2 * h)).isApprox(s.theta2, 1e-5));
  }
}

// The IMU of a vibrating body must describe the pose the renderer draws: velocity,
// acceleration and angular rate of BodyMotion::State agree with the numeric derivatives of
// BodyMotion::WorldFromBody.
TEST(Vibration, PerturbedStateIsConsistentWithThePerturbedPose) {
  const SplineTrajectory spline = RandomTestFlight(MotionLevel::kDifficult, 6.0, 3);
  VibrationOptions options;
  options.scale = 3.0;  // make the perturbation dominate the numeric check
  const BodyMotion body(spline, Vibration(EurocVibrationSpectrum(), options, 4));
  const std::int64_t h = 20'000;  // 20 us
  for (std::int64_t t : {1'000'000'000LL, 2'345'678'901LL, 4'500'000'000LL}) {
    const BodyState s = body.State(t);
    const SE3d a = body.WorldFromBody(t - h);
    const SE3d b = body.WorldFromBody(t + h);
    const SE3d c = body.WorldFromBody(t);
    const double dt = 1e-9 * static_cast<double>(h);
    const Eigen::Vector3d v_num = (b.translation() - a.translation()) / (2 * dt);
    const Eigen::Vector3d a_num =
        (b.translation() - 2 * c.translation() + a.translation()) / (dt * dt);
    const Eigen::Vector3d w_num = (a.so3().Inverse() * b.so3()).Log() / (2 * dt);
    EXPECT_LT((v_num - s.velocity_world).norm(), 1e-6) << t;
    EXPECT_LT((a_num - s.acceleration_world).norm(), 2e-3 * (1.0 + s.acceleration_world.norm()))
        << t;
    EXPECT_LT((w_num - s.omega_body).norm(), 1e-5) << t;
    // And the vibration is there: the perturbed state differs from the smooth one.
    EXPECT_GT((s.acceleration_world - spline.State(t).acceleration_world).norm(), 0.05);
  }
}

TEST(Vibration, BadSpectrumOrOptionsAreRejected) {
  VibrationSpectrum s;
  s.bins.push_back({10.0, 8.0, {}});
  EXPECT_THROW(s.Check(), OptionError);
  VibrationOptions o;
  o.tones_per_bin = 0;
  EXPECT_THROW(o.Check(), OptionError);
}

}  // namespace
}  // namespace pkslam::sim
