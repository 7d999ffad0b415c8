#include "imu/preintegration.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "core/util/error.h"
#include "imu/imu_test_utils.h"

namespace pkslam {
namespace {

using testing::HelixMotion;
using testing::kTestGravity;
using testing::SampleImu;
using testing::Seconds;
using Vec3 = Eigen::Vector3d;

constexpr std::int64_t kSecond = 1'000'000'000;

// The true deltas of `motion` over [t0, t1] (see core/imu/imu_types.h).
struct TrueDeltas {
  SO3d dR;
  Vec3 dv, dp;
};
TrueDeltas TruthBetween(const HelixMotion& motion, double t0, double t1) {
  const NavState a = motion.State(t0);
  const NavState b = motion.State(t1);
  const SO3d rt = a.world_from_body.so3().Inverse();
  const double dt = t1 - t0;
  return {rt * b.world_from_body.so3(),
          rt * (b.velocity_world - a.velocity_world - kTestGravity * dt),
          rt * (b.world_from_body.translation() - a.world_from_body.translation() -
                a.velocity_world * dt - 0.5 * kTestGravity * dt * dt)};
}

PreintegratedImu Integrate(const std::vector<ImuMeasurement>& samples, std::int64_t t0,
                           std::int64_t t1, const ImuBias& bias = {},
                           ImuIntegrationScheme scheme = ImuIntegrationScheme::kMidpoint) {
  PreintegratedImu pim = StartPreintegration(bias, ImuNoise{}, scheme);
  IntegrateSamples(samples, t0, t1, &pim);
  return pim;
}

// One second of the helix, sampled every 5 ms without noise by an IMU with bias kHelixBias and
// integrated at that bias.
const ImuBias kHelixBias(Vec3(0.01, -0.02, 0.015), Vec3(0.1, 0.05, -0.2));
PreintegratedImu HelixSecond(ImuIntegrationScheme scheme) {
  const HelixMotion motion;
  return Integrate(SampleImu(motion, 0, kSecond, 5'000'000, kHelixBias, {}, nullptr), 0, kSecond,
                   kHelixBias, scheme);
}

constexpr ImuIntegrationScheme kSchemes[] = {ImuIntegrationScheme::kMidpoint,
                                             ImuIntegrationScheme::kOrbSlam3};

TEST(Preintegration, ExactMotionConvergesWithSamplePeriod) {
  const HelixMotion motion;
  const std::int64_t t0 = kSecond / 2;
  const std::int64_t t1 = t0 + 2 * kSecond;
  const TrueDeltas truth = TruthBetween(motion, Seconds(t0), Seconds(t1));
  for (const ImuIntegrationScheme scheme : kSchemes) {
    const bool midpoint = scheme == ImuIntegrationScheme::kMidpoint;
    std::vector<double> err_r, err_v, err_p;
    for (const std::int64_t period : {20'000'000, 10'000'000, 5'000'000, 2'500'000}) {
      const PreintegratedImu pim =
          Integrate(SampleImu(motion, t0, t1, period, {}, {}, nullptr), t0, t1, {}, scheme);
      EXPECT_NEAR(pim.dt, 2.0, 1e-12);
      err_r.push_back((truth.dR.Inverse() * pim.delta_R).Angle());
      err_v.push_back((pim.delta_v - truth.dv).norm());
      err_p.push_back((pim.delta_p - truth.dp).norm());
      std::printf(
          "[ scheme %s ] period %5.2f ms: |dR err| %.3e rad, |dv err| %.3e m/s, "
          "|dp err| %.3e m\n",
          midpoint ? "midpoint" : "orbslam3", 1e-6 * static_cast<double>(period), err_r.back(),
          err_v.back(), err_p.back());
    }
    for (std::size_t k = 1; k < err_r.size(); ++k) {
      // Second order: x1/4 per halving of the period; first order: x1/2.
      EXPECT_LT(err_r[k], 0.3 * err_r[k - 1]) << k;
      EXPECT_LT(err_v[k], (midpoint ? 0.3 : 0.6) * err_v[k - 1]) << k;
      EXPECT_LT(err_p[k], (midpoint ? 0.3 : 0.6) * err_p[k - 1]) << k;
    }
    // At 200 Hz (index 2) the midpoint errors are far below what EuRoC's noise adds over 2 s
    // (~sigma_a sqrt(T) = 2.8e-3 m/s, sigma_g sqrt(T) = 2.4e-4 rad); ORB-SLAM3's velocity
    // error is not.
    EXPECT_LT(err_r[2], 2e-5);
    if (midpoint) {
      EXPECT_LT(err_v[2], 2e-4);
      EXPECT_LT(err_p[2], 2e-4);
    } else {
      EXPECT_GT(err_v[2], 3e-3);
    }
  }
}

class PreintegrationSchemes : public ::testing::TestWithParam<ImuIntegrationScheme> {};

INSTANTIATE_TEST_SUITE_P(Both, PreintegrationSchemes, ::testing::ValuesIn(kSchemes));

TEST_P(PreintegrationSchemes, BiasJacobiansMatchNumericDifferences) {
  const HelixMotion motion;
  const std::int64_t t0 = 0, t1 = kSecond;
  const ImuBias b0(Vec3(0.01, -0.02, 0.015), Vec3(0.1, 0.05, -0.2));
  const std::vector<ImuMeasurement> samples = SampleImu(motion, t0, t1, 5'000'000, b0, {}, nullptr);
  const PreintegratedImu pim = Integrate(samples, t0, t1, b0, GetParam());
  const double h = 1e-6;
  Eigen::Matrix3d n_R_bg, n_v_bg, n_v_ba, n_p_bg, n_p_ba;
  for (int i = 0; i < 6; ++i) {
    PreintegratedImu plus = pim, minus = pim;
    ImuBias bp = b0, bm = b0;
    if (i < 3) {
      bp.gyro(i) += h;
      bm.gyro(i) -= h;
    } else {
      bp.accel(i - 3) += h;
      bm.accel(i - 3) -= h;
    }
    Reintegrate(bp, &plus);
    Reintegrate(bm, &minus);
    const Vec3 d_r = (minus.delta_R.Inverse() * plus.delta_R).Log() / (2 * h);
    const Vec3 d_v = (plus.delta_v - minus.delta_v) / (2 * h);
    const Vec3 d_p = (plus.delta_p - minus.delta_p) / (2 * h);
    if (i < 3) {
      n_R_bg.col(i) = d_r;
      n_v_bg.col(i) = d_v;
      n_p_bg.col(i) = d_p;
    } else {
      EXPECT_LT(d_r.norm(), 1e-9);  // the accel bias does not rotate
      n_v_ba.col(i - 3) = d_v;
      n_p_ba.col(i - 3) = d_p;
    }
  }
  EXPECT_LT((n_R_bg - pim.J_R_bg).norm(), 1e-6 * (1 + pim.J_R_bg.norm())) << pim.J_R_bg;
  EXPECT_LT((n_v_bg - pim.J_v_bg).norm(), 1e-5 * (1 + pim.J_v_bg.norm())) << pim.J_v_bg;
  EXPECT_LT((n_p_bg - pim.J_p_bg).norm(), 1e-5 * (1 + pim.J_p_bg.norm())) << pim.J_p_bg;
  EXPECT_LT((n_v_ba - pim.J_v_ba).norm(), 1e-6 * (1 + pim.J_v_ba.norm()));
  EXPECT_LT((n_p_ba - pim.J_p_ba).norm(), 1e-6 * (1 + pim.J_p_ba.norm()));
  // Not trivially small: over 1 s of rotation they are O(1).
  EXPECT_GT(pim.J_R_bg.norm(), 0.5);
  EXPECT_GT(pim.J_p_bg.norm(), 0.05);
}

TEST_P(PreintegrationSchemes, GyroScaleJacobiansMatchRescaledReintegration) {
  // The gyro reads (1 + k) times the rate: the Jacobians give the deltas of rates divided by
  // 1 + dk, which RescaleGyro(1 / (1 + dk)) integrates exactly.
  const ImuBias& b0 = kHelixBias;
  const PreintegratedImu pim = HelixSecond(GetParam());
  const GyroScaleJacobians j = GyroScaleJacobiansOf(pim);
  const double h = 1e-6;
  Eigen::Matrix3d n_R, n_v, n_p;
  for (int i = 0; i < 3; ++i) {
    PreintegratedImu plus = pim, minus = pim;
    Vec3 fp = Vec3::Ones(), fm = Vec3::Ones();
    fp(i) = 1.0 / (1.0 + h);
    fm(i) = 1.0 / (1.0 - h);
    RescaleGyro(fp, &plus);
    RescaleGyro(fm, &minus);
    // RescaleGyro also scales the linearisation bias; compare at the original bias.
    n_R.col(i) = (DeltaRotation(minus, b0).Inverse() * DeltaRotation(plus, b0)).Log() / (2 * h);
    n_v.col(i) = (DeltaVelocity(plus, b0) - DeltaVelocity(minus, b0)) / (2 * h);
    n_p.col(i) = (DeltaPosition(plus, b0) - DeltaPosition(minus, b0)) / (2 * h);
  }
  EXPECT_LT((n_R - j.rotation).norm(), 1e-5 * (1 + j.rotation.norm())) << j.rotation;
  EXPECT_LT((n_v - j.velocity).norm(), 1e-4 * (1 + j.velocity.norm())) << j.velocity;
  EXPECT_LT((n_p - j.position).norm(), 1e-4 * (1 + j.position.norm())) << j.position;
  // Over a second of the helix's turning a 1% scale error is a visible rotation.
  EXPECT_GT(j.rotation.norm(), 0.1);
  EXPECT_GT(j.velocity.norm(), 0.1);
}

TEST_P(PreintegrationSchemes, AccelAxesJacobiansMatchTransformedReintegration) {
  // A change dE' of the corrected samples' axis errors multiplies them by (I + dE')^-1, which
  // TransformAccel integrates exactly; the bias is held (compared at b0).
  const ImuBias& b0 = kHelixBias;
  const PreintegratedImu pim = HelixSecond(GetParam());
  const AccelAxesJacobians j = AccelAxesJacobiansOf(pim);
  const double h = 1e-6;
  Eigen::Matrix<double, 3, 9> n_v, n_p;
  for (int i = 0; i < 9; ++i) {
    Eigen::Matrix3d e = Eigen::Matrix3d::Zero();
    e(i / 3, i % 3) = h;
    PreintegratedImu plus = pim, minus = pim;
    TransformAccel((Eigen::Matrix3d::Identity() + e).inverse(), &plus);
    TransformAccel((Eigen::Matrix3d::Identity() - e).inverse(), &minus);
    EXPECT_LT((DeltaRotation(minus, b0).Inverse() * DeltaRotation(plus, b0)).Log().norm(), 1e-12);
    n_v.col(i) = (DeltaVelocity(plus, b0) - DeltaVelocity(minus, b0)) / (2 * h);
    n_p.col(i) = (DeltaPosition(plus, b0) - DeltaPosition(minus, b0)) / (2 * h);
  }
  EXPECT_LT((n_v - j.velocity).norm(), 1e-5 * (1 + j.velocity.norm())) << j.velocity;
  EXPECT_LT((n_p - j.position).norm(), 1e-5 * (1 + j.position.norm())) << j.position;
  // Gravity alone is ~9.8 m/s^2 on one axis: a 1% error of it is ~0.1 m/s over the second.
  EXPECT_GT(j.velocity.norm(), 5.0);
}

TEST(Preintegration, TransformAccelByIdentityChangesNothingAndRejectsSingularMatrices) {
  const ImuBias& b0 = kHelixBias;
  const PreintegratedImu pim = HelixSecond(ImuIntegrationScheme::kMidpoint);
  PreintegratedImu same = pim;
  TransformAccel(Eigen::Matrix3d::Identity(), &same);
  EXPECT_EQ(same.delta_v, pim.delta_v);
  EXPECT_EQ(same.covariance, pim.covariance);
  PreintegratedImu scaled = pim;
  TransformAccel(Eigen::Vector3d(1.01, 1.0, 1.0).asDiagonal(), &scaled);
  EXPECT_NEAR(scaled.bias.accel.x(), 1.01 * b0.accel.x(), 1e-15);
  EXPECT_GT((scaled.delta_v - pim.delta_v).norm(), 1e-3);
  EXPECT_THROW(TransformAccel(Eigen::Matrix3d::Zero(), &scaled), Error);
}

TEST(Preintegration, RescaleGyroByOneChangesNothingAndRejectsBadFactors) {
  const ImuBias& b0 = kHelixBias;
  const PreintegratedImu pim = HelixSecond(ImuIntegrationScheme::kMidpoint);
  PreintegratedImu same = pim;
  RescaleGyro(Vec3::Ones(), &same);
  EXPECT_EQ(same.delta_v, pim.delta_v);
  EXPECT_EQ(same.covariance, pim.covariance);
  PreintegratedImu scaled = pim;
  RescaleGyro(Vec3(1.01, 1.0, 1.0), &scaled);
  EXPECT_NEAR(scaled.bias.gyro.x(), 1.01 * b0.gyro.x(), 1e-15);
  EXPECT_GT((scaled.delta_R.Inverse() * pim.delta_R).Angle(), 1e-4);
  EXPECT_THROW(RescaleGyro(Vec3(1.0, 0.0, 1.0), &scaled), Error);
  EXPECT_THROW(RescaleGyro(Vec3(1.0, std::nan(""), 1.0), &scaled), Error);
}

TEST(Preintegration, FirstOrderBiasCorrectionApproximatesReintegration) {
  const HelixMotion motion;
  const std::int64_t t0 = 0, t1 = kSecond / 2;
  const std::vector<ImuMeasurement> samples = SampleImu(motion, t0, t1, 5'000'000, {}, {}, nullptr);
  const PreintegratedImu pim = Integrate(samples, t0, t1);
  // The remainders are second order in the gyro-bias change: x1/4 when it halves.
  double prev[3] = {0, 0, 0};
  for (const double step : {0.01, 0.005}) {
    const ImuBias nb(Vec3(step, -step, step), Vec3(10 * step, 5 * step, -10 * step));
    PreintegratedImu exact = pim;
    Reintegrate(nb, &exact);
    const double e[3] = {(exact.delta_R.Inverse() * DeltaRotation(pim, nb)).Angle(),
                         (exact.delta_v - DeltaVelocity(pim, nb)).norm(),
                         (exact.delta_p - DeltaPosition(pim, nb)).norm()};
    std::printf("[ bias correction ] |d b_g| %.4f rad/s: errors %.2e rad, %.2e m/s, %.2e m\n",
                step * std::sqrt(3.0), e[0], e[1], e[2]);
    // Below the noise over 0.5 s (sigma_g sqrt(T) = 1.2e-4 rad, sigma_a sqrt(T) = 1.4e-3 m/s).
    EXPECT_LT(e[0], 1.2e-4);
    EXPECT_LT(e[1], 1.4e-3);
    for (int k = 0; k < 3 && prev[0] > 0; ++k) EXPECT_LT(e[k], 0.3 * prev[k]) << k;
    std::copy(e, e + 3, prev);
  }
  // Accel bias alone: the correction is exact.
  const ImuBias accel_only(Vec3::Zero(), Vec3(0.3, -0.2, 0.1));
  PreintegratedImu exact = pim;
  Reintegrate(accel_only, &exact);
  EXPECT_LT((exact.delta_v - DeltaVelocity(pim, accel_only)).norm(), 1e-12);
  EXPECT_LT((exact.delta_p - DeltaPosition(pim, accel_only)).norm(), 1e-12);
}

// Sample covariance of [Log(dR_true^T dR), dv - dv_true, dp - dp_true] over noisy runs.
template <typename Run>
Eigen::Matrix<double, 9, 9> MonteCarloCovariance(int runs, const PreintegratedImu& clean, Run run) {
  Eigen::Matrix<double, 9, 9> cov = Eigen::Matrix<double, 9, 9>::Zero();
  for (int k = 0; k < runs; ++k) {
    const PreintegratedImu noisy = run(k);
    Eigen::Matrix<double, 9, 1> e;
    e << (clean.delta_R.Inverse() * noisy.delta_R).Log(), noisy.delta_v - clean.delta_v,
        noisy.delta_p - clean.delta_p;
    cov += e * e.transpose();
  }
  return cov / runs;
}

// Relative error of each 3x3 diagonal block's trace and of the whole matrix.
void ExpectCovarianceClose(const Eigen::Matrix<double, 9, 9>& predicted,
                           const Eigen::Matrix<double, 9, 9>& sampled, double tolerance) {
  const Eigen::Matrix<double, 9, 9> w = SqrtInformation<9>(predicted);
  const Eigen::Matrix<double, 9, 9> white = w * sampled * w.transpose();
  std::printf(
      "[ covariance ] sampled/predicted trace: rotation %.3f, velocity %.3f, position "
      "%.3f; whitened trace/9 %.3f, max |whitened - I| %.3f\n",
      sampled.block<3, 3>(0, 0).trace() / predicted.block<3, 3>(0, 0).trace(),
      sampled.block<3, 3>(3, 3).trace() / predicted.block<3, 3>(3, 3).trace(),
      sampled.block<3, 3>(6, 6).trace() / predicted.block<3, 3>(6, 6).trace(), white.trace() / 9.0,
      (white - Eigen::Matrix<double, 9, 9>::Identity()).cwiseAbs().maxCoeff());
  for (Eigen::Index b = 0; b < 9; b += 3) {
    const double p = predicted.block<3, 3>(b, b).trace();
    const double s = sampled.block<3, 3>(b, b).trace();
    EXPECT_NEAR(s / p, 1.0, tolerance) << "block " << b << " predicted " << p << " sampled " << s;
  }
  // Whitened: the sampled covariance in the predicted metric should be near identity.
  EXPECT_NEAR(white.trace() / 9.0, 1.0, tolerance);
  EXPECT_LT((white - Eigen::Matrix<double, 9, 9>::Identity()).cwiseAbs().maxCoeff(), 3 * tolerance);
}

TEST_P(PreintegrationSchemes, CovarianceMatchesMonteCarloPerStepNoise) {
  // The propagation model exactly: independent discrete noise on each step's inputs.
  const HelixMotion motion;
  const ImuNoise noise;
  const double dt = 1.0 / noise.rate_hz;
  const int steps = 100;  // 0.5 s
  PreintegratedImu clean = StartPreintegration({}, noise, GetParam());
  for (int i = 0; i < steps; ++i) {
    IntegrateMeasurement(motion.Accel(i * dt, kTestGravity), motion.Gyro(i * dt), dt, &clean);
  }
  const double sg = noise.gyro_noise_density * std::sqrt(noise.rate_hz);
  const double sa = noise.accel_noise_density * std::sqrt(noise.rate_hz);
  std::mt19937 rng(7);
  std::normal_distribution<double> n01(0.0, 1.0);
  const auto run = [&](int) {
    PreintegratedImu p = StartPreintegration({}, noise, GetParam());
    for (const PreintegratedImu::Step& s : clean.steps) {
      const Vec3 ng(n01(rng), n01(rng), n01(rng));
      const Vec3 na(n01(rng), n01(rng), n01(rng));
      IntegrateMeasurement(s.accel + sa * na, s.gyro + sg * ng, s.dt, &p);
    }
    return p;
  };
  const Eigen::Matrix<double, 9, 9> sampled = MonteCarloCovariance(3000, clean, run);
  ExpectCovarianceClose(clean.covariance.topLeftCorner<9, 9>(), sampled, 0.1);
}

TEST(Preintegration, CovarianceMatchesMonteCarloSampleNoise) {
  // Noise on the raw 200 Hz samples, integrated with the mean of consecutive samples: adjacent
  // steps share a sample, which the propagation ignores; the totals still agree within ~20%.
  const HelixMotion motion;
  const ImuNoise noise;
  const std::int64_t t0 = 0, t1 = kSecond / 2, period = 5'000'000;
  const PreintegratedImu clean =
      Integrate(SampleImu(motion, t0, t1, period, {}, noise, nullptr), t0, t1);
  std::mt19937 rng(11);
  const auto run = [&](int) {
    return Integrate(SampleImu(motion, t0, t1, period, {}, noise, &rng), t0, t1);
  };
  const Eigen::Matrix<double, 9, 9> sampled = MonteCarloCovariance(2000, clean, run);
  ExpectCovarianceClose(clean.covariance.topLeftCorner<9, 9>(), sampled, 0.2);
}

TEST(Preintegration, BiasWalkCovarianceGrowsWithTime) {
  const ImuNoise noise;
  PreintegratedImu pim = StartPreintegration({}, noise);
  for (int i = 0; i < 40; ++i) IntegrateMeasurement(Vec3(0, 0, 9.81), Vec3::Zero(), 0.005, &pim);
  IntegrateMeasurement(Vec3(0, 0, 9.81), Vec3::Zero(), 0.0012, &pim);  // a partial step
  const double t = 0.2012;
  const Eigen::Matrix<double, 6, 6> walk = pim.covariance.bottomRightCorner<6, 6>();
  EXPECT_NEAR(walk(0, 0), noise.gyro_random_walk * noise.gyro_random_walk * t, 1e-20);
  EXPECT_NEAR(walk(5, 5), noise.accel_random_walk * noise.accel_random_walk * t, 1e-16);
  EXPECT_EQ(walk(0, 1), 0.0);
  EXPECT_TRUE((pim.covariance.block<9, 6>(0, 9).isZero()));
}

// ORB-SLAM3's Tracking::PreintegrateIMU interval rules, written out independently: samples
// s_0 <= t_begin < s_1 < ... < s_{n-1} < t_end <= s_n.
std::vector<PreintegratedImu::Step> OrbSlam3Steps(const std::vector<ImuMeasurement>& s,
                                                  std::int64_t t_begin, std::int64_t t_end) {
  std::vector<PreintegratedImu::Step> out;
  const int n = static_cast<int>(s.size()) - 1;
  for (int i = 0; i < n; ++i) {
    const double tab = Seconds(s[i + 1].t_ns - s[i].t_ns);
    PreintegratedImu::Step st;
    if (i == 0) {
      const double tini = Seconds(s[i].t_ns - t_begin);
      st.accel = (s[i].accel + s[i + 1].accel - (s[i + 1].accel - s[i].accel) * (tini / tab)) / 2;
      st.gyro = (s[i].gyro + s[i + 1].gyro - (s[i + 1].gyro - s[i].gyro) * (tini / tab)) / 2;
      st.dt = Seconds(s[i + 1].t_ns - t_begin);
    } else if (i < n - 1) {
      st.accel = (s[i].accel + s[i + 1].accel) / 2;
      st.gyro = (s[i].gyro + s[i + 1].gyro) / 2;
      st.dt = tab;
    } else {
      const double tend = Seconds(s[i + 1].t_ns - t_end);
      st.accel = (s[i].accel + s[i + 1].accel - (s[i + 1].accel - s[i].accel) * (tend / tab)) / 2;
      st.gyro = (s[i].gyro + s[i + 1].gyro - (s[i + 1].gyro - s[i].gyro) * (tend / tab)) / 2;
      st.dt = Seconds(t_end - s[i].t_ns);
    }
    out.push_back(st);
  }
  return out;
}

TEST(Preintegration, FrameIntervalsMatchOrbSlam3) {
  const HelixMotion motion;
  const std::vector<ImuMeasurement> samples =
      SampleImu(motion, 0, kSecond, 5'000'000, {}, {}, nullptr);
  // A frame interval with both ends between samples.
  const std::int64_t t_begin = 101'300'000, t_end = 151'700'000;
  std::vector<ImuMeasurement> window;
  for (const ImuMeasurement& s : samples) {
    if (s.t_ns >= 100'000'000 && s.t_ns <= 155'000'000) window.push_back(s);
  }
  PreintegratedImu pim = StartPreintegration({}, {});
  EXPECT_EQ(IntegrateSamples(window, t_begin, t_end, &pim), 11);
  const std::vector<PreintegratedImu::Step> expected = OrbSlam3Steps(window, t_begin, t_end);
  ASSERT_EQ(pim.steps.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_NEAR(pim.steps[i].dt, expected[i].dt, 1e-15) << i;
    EXPECT_LT((pim.steps[i].accel - expected[i].accel).norm(), 1e-12) << i;
    EXPECT_LT((pim.steps[i].gyro - expected[i].gyro).norm(), 1e-12) << i;
  }
  EXPECT_NEAR(pim.dt, 0.0504, 1e-15);
  // Samples that do not reach the ends are held; extra samples outside are ignored.
  PreintegratedImu held = StartPreintegration({}, {});
  EXPECT_EQ(IntegrateSamples({samples[10]}, t_begin, t_end, &held), 1);
  EXPECT_EQ(held.steps[0].accel, samples[10].accel);
  PreintegratedImu all = StartPreintegration({}, {});
  IntegrateSamples(samples, t_begin, t_end, &all);
  EXPECT_EQ(all.delta_p, pim.delta_p);
}

TEST(Preintegration, RejectsBadInput) {
  PreintegratedImu pim = StartPreintegration({}, {});
  EXPECT_THROW(IntegrateSamples({}, 0, 10, &pim), Error);
  ImuMeasurement a, b;
  a.t_ns = 5;
  b.t_ns = 5;
  EXPECT_THROW(IntegrateSamples({a, b}, 0, 10, &pim), Error);
  EXPECT_THROW(IntegrateSamples({a}, 10, 10, &pim), Error);
  EXPECT_THROW(IntegrateMeasurement(Vec3::Zero(), Vec3::Zero(), 0.0, &pim), Error);
  EXPECT_THROW(IntegrateMeasurement(Vec3(NAN, 0, 0), Vec3::Zero(), 0.005, &pim), Error);
  ImuNoise bad;
  bad.rate_hz = 0;
  EXPECT_THROW(StartPreintegration({}, bad), OptionError);
  PreintegrationOptions options;
  options.reintegrate_gyro_bias_change = -1;
  EXPECT_THROW(options.Check(), OptionError);
}

TEST(Preintegration, PredictStateReproducesMotionWithBias) {
  const HelixMotion motion;
  const std::int64_t t0 = kSecond, t1 = kSecond + kSecond / 4;
  const ImuBias bias(Vec3(0.02, -0.01, 0.03), Vec3(-0.2, 0.1, 0.15));
  // Integrated at zero bias, predicted with the true bias through the first-order correction.
  const PreintegratedImu pim =
      Integrate(SampleImu(motion, t0, t1, 2'500'000, bias, {}, nullptr), t0, t1);
  const NavState predicted = PredictState(motion.State(Seconds(t0)), pim, bias, kTestGravity);
  const NavState truth = motion.State(Seconds(t1));
  EXPECT_LT((truth.world_from_body.so3().Inverse() * predicted.world_from_body.so3()).Angle(),
            1e-4);
  EXPECT_LT((truth.velocity_world - predicted.velocity_world).norm(), 2e-3);
  EXPECT_LT((truth.world_from_body.translation() - predicted.world_from_body.translation()).norm(),
            5e-4);
  // Without the bias the prediction is visibly off.
  const NavState wrong = PredictState(motion.State(Seconds(t0)), pim, {}, kTestGravity);
  EXPECT_GT((truth.velocity_world - wrong.velocity_world).norm(), 0.03);
}

TEST(Preintegration, MergePreviousEqualsIntegratingTheUnion) {
  const HelixMotion motion;
  const std::vector<ImuMeasurement> samples =
      SampleImu(motion, 0, kSecond, 5'000'000, {}, {}, nullptr);
  const ImuBias bias(Vec3(0.01, 0, 0), Vec3(0, 0.1, 0));
  const std::int64_t ta = 12'000'000, tb = 333'000'000, tc = 702'000'000;
  PreintegratedImu first = StartPreintegration({}, {});  // a different bias: replaced
  IntegrateSamples(samples, ta, tb, &first);
  PreintegratedImu second = StartPreintegration(bias, {});
  IntegrateSamples(samples, tb, tc, &second);
  PreintegratedImu direct = StartPreintegration(bias, {});
  IntegrateSamples(samples, ta, tb, &direct);
  IntegrateSamples(samples, tb, tc, &direct);
  MergePrevious(first, &second);
  EXPECT_EQ(second.steps.size(), direct.steps.size());
  EXPECT_EQ(second.bias, bias);
  EXPECT_NEAR(second.dt, Seconds(tc - ta), 1e-12);
  EXPECT_EQ(second.delta_p, direct.delta_p);
  EXPECT_EQ(second.covariance, direct.covariance);
  EXPECT_EQ(second.J_p_bg, direct.J_p_bg);
}

TEST(Preintegration, UpdateBiasReintegratesOnlyWhenFar) {
  const HelixMotion motion;
  const std::vector<ImuMeasurement> samples =
      SampleImu(motion, 0, kSecond / 2, 5'000'000, {}, {}, nullptr);
  const PreintegratedImu pim = Integrate(samples, 0, kSecond / 2);
  const PreintegrationOptions options;  // 0.01 rad/s
  PreintegratedImu near = pim;
  EXPECT_FALSE(UpdateBias(ImuBias(Vec3(0.005, 0, 0), Vec3(1, 1, 1)), options, &near));
  EXPECT_EQ(near.bias, ImuBias());
  EXPECT_EQ(near.delta_v, pim.delta_v);
  PreintegratedImu far = pim;
  const ImuBias moved(Vec3(0.02, 0, 0), Vec3::Zero());
  EXPECT_TRUE(UpdateBias(moved, options, &far));
  EXPECT_EQ(far.bias, moved);
  PreintegratedImu expected = pim;
  Reintegrate(moved, &expected);
  EXPECT_EQ(far.delta_R.quaternion().coeffs(), expected.delta_R.quaternion().coeffs());
  EXPECT_GT((far.delta_v - pim.delta_v).norm(), 1e-3);
}

TEST(Preintegration, AveragesAreBiasCorrected) {
  PreintegratedImu pim = StartPreintegration(ImuBias(Vec3(0.1, 0, 0), Vec3(0, 0, 1)), {});
  IntegrateMeasurement(Vec3(0, 0, 10.81), Vec3(0.1, 0, 0), 0.01, &pim);
  IntegrateMeasurement(Vec3(0, 0, 10.81), Vec3(0.1, 0, 0), 0.03, &pim);
  EXPECT_LT((pim.average_accel - Vec3(0, 0, 9.81)).norm(), 1e-12);
  EXPECT_LT(pim.average_gyro.norm(), 1e-15);
}

}  // namespace
}  // namespace pkslam
