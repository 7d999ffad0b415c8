#include "sim/bspline.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sim/spline_fit.h"

namespace pkslam::sim {
namespace {

TEST(UniformBasis, WeightsSumToOneAndCumulativeStartsAtOne) {
  const UniformBasis<6> basis;
  for (double u : {0.0, 0.3, 0.77, 1.0}) {
    EXPECT_NEAR(basis.Weights(u, 1.0, 0, false).sum(), 1.0, 1e-12);
    EXPECT_NEAR(basis.Weights(u, 1.0, 1, false).sum(), 0.0, 1e-12);
    EXPECT_NEAR(basis.Weights(u, 1.0, 0, true)[0], 1.0, 1e-12);
  }
  // Cubic: the well-known (1, 4, 1) / 6 at u = 0.
  const UniformBasis<4> cubic;
  const auto w = cubic.Weights(0.0, 1.0, 0, false);
  EXPECT_NEAR(w[0], 1.0 / 6, 1e-12);
  EXPECT_NEAR(w[1], 4.0 / 6, 1e-12);
  EXPECT_NEAR(w[2], 1.0 / 6, 1e-12);
  EXPECT_NEAR(w[3], 0.0, 1e-12);
}

TEST(PositionSpline, DerivativesMatchFiniteDifferences) {
  KnotGrid grid{1'000'000'000, 100'000'000, 10};
  std::vector<Eigen::Vector3d> control;
  for (int i = 0; i < PositionSpline6::NumControl(grid); ++i) {
    control.emplace_back(std::sin(i), std::cos(0.7 * i), 0.1 * i * i);
  }
  const PositionSpline6 spline(grid, control);
  const std::int64_t t = 1'000'000'000 + 437'000'000;
  const std::int64_t h = 10'000;  // 10 us
  Eigen::Vector3d v, a, j;
  spline.Evaluate(t, &v, &a, &j);
  const Eigen::Vector3d fd_v = (spline.Evaluate(t + h) - spline.Evaluate(t - h)) / 2e-5;
  Eigen::Vector3d v_plus, v_minus, a_plus, a_minus;
  spline.Evaluate(t + h, &v_plus, &a_plus);
  spline.Evaluate(t - h, &v_minus, &a_minus);
  EXPECT_LT((v - fd_v).norm(), 1e-6);
  EXPECT_LT((a - (v_plus - v_minus) / 2e-5).norm(), 1e-5);
  EXPECT_LT((j - (a_plus - a_minus) / 2e-5).norm(), 1e-3);
}

TEST(RotationSpline, AngularVelocityAndAccelerationMatchFiniteDifferences) {
  KnotGrid grid{0, 200'000'000, 8};
  std::vector<SO3d> control;
  for (int i = 0; i < RotationSpline4::NumControl(grid); ++i) {
    control.push_back(SO3d::Exp(Eigen::Vector3d(0.3 * i, std::sin(i), 0.2 * i * i)));
  }
  const RotationSpline4 spline(grid, control);
  const std::int64_t t = 777'000'000;
  const std::int64_t h = 1'000;
  Eigen::Vector3d omega, alpha;
  const SO3d r = spline.Evaluate(t, &omega, &alpha);
  const Eigen::Vector3d fd_omega =
      (spline.Evaluate(t - h).Inverse() * spline.Evaluate(t + h)).Log() / 2e-6;
  EXPECT_LT((omega - fd_omega).norm(), 1e-5 * (1.0 + omega.norm()));
  Eigen::Vector3d omega_plus, omega_minus;
  spline.Evaluate(t + h, &omega_plus);
  spline.Evaluate(t - h, &omega_minus);
  EXPECT_LT((alpha - (omega_plus - omega_minus) / 2e-6).norm(), 1e-3 * (1.0 + alpha.norm()));
  EXPECT_NEAR(r.quaternion().norm(), 1.0, 1e-12);
}

TEST(RotationSpline, ContinuousAcrossKnots) {
  KnotGrid grid{0, 100'000'000, 5};
  std::vector<SO3d> control;
  for (int i = 0; i < RotationSpline4::NumControl(grid); ++i) {
    control.push_back(SO3d::Exp(Eigen::Vector3d(0.5 * i, -0.2 * i, 0.1)));
  }
  const RotationSpline4 spline(grid, control);
  Eigen::Vector3d w_before, w_after;
  const SO3d before = spline.Evaluate(200'000'000 - 1, &w_before);
  const SO3d after = spline.Evaluate(200'000'000, &w_after);
  EXPECT_LT((before.Inverse() * after).Log().norm(), 1e-6);
  EXPECT_LT((w_before - w_after).norm(), 1e-6);
}

TEST(SplineFit, RecoversSmoothMotionFromNoisySamples) {
  // 4 s of a smooth curve sampled at 200 Hz with 0.1 mm noise.
  std::vector<std::int64_t> t;
  std::vector<Eigen::Vector3d> p;
  std::vector<SO3d> r;
  std::uint64_t state = 12345;
  auto noise = [&state]() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return (static_cast<double>(state >> 11) * 0x1.0p-53 - 0.5) * 2.0 *
           0.000173;  // sd 0.1 mm (10x EuRoC ground truth)
  };
  auto truth_p = [](double s) {
    return Eigen::Vector3d(std::sin(s), 0.5 * std::cos(1.3 * s), 0.2 * s);
  };
  auto truth_r = [](double s) {
    return SO3d::Exp(Eigen::Vector3d(0.3 * s, 0.2 * std::sin(s), 0.1));
  };
  for (int k = 0; k <= 800; ++k) {
    const double s = k * 0.005;
    t.push_back(k * std::int64_t{5'000'000});
    p.push_back(truth_p(s) + Eigen::Vector3d(noise(), noise(), noise()));
    r.push_back(truth_r(s) * SO3d::Exp(Eigen::Vector3d(noise(), noise(), noise())));
  }
  const KnotGrid grid = KnotGrid::Covering(t.front(), t.back(), 50'000'000);
  const PositionSpline6 ps = FitPositionSpline(t, p, grid, 6.0);
  const RotationSpline4 rs = FitRotationSpline(t, r, grid, 6.0);
  double max_p = 0, max_r = 0, max_a = 0;
  for (int k = 100; k <= 700; ++k) {  // away from the ends
    const double s = k * 0.005;
    Eigen::Vector3d v, a;
    max_p = std::max(max_p, (ps.Evaluate(t[k], &v, &a) - truth_p(s)).norm());
    const Eigen::Vector3d a_true(-std::sin(s), -0.5 * 1.69 * std::cos(1.3 * s), 0.0);
    max_a = std::max(max_a, (a - a_true).norm());
    max_r = std::max(max_r, (truth_r(s).Inverse() * rs.Evaluate(t[k])).Log().norm());
  }
  EXPECT_LT(max_p, 0.0002);
  EXPECT_LT(max_r, 0.0002);
  EXPECT_LT(max_a, 0.1);  // noise alone would give metres/s^2 if differentiated directly
}

}  // namespace
}  // namespace pkslam::sim
