#include "core/geometry/so3.h"

#include <gtest/gtest.h>

#include <ceres/jet.h>

#include "core/geometry/lie_test_utils.h"

namespace pkslam {
namespace {

using testing::NumericRightJacobian;
using testing::RandomTangent;

TEST(SO3, ExpLogRoundTripAcrossAngles) {
  std::mt19937 rng(1);
  for (double scale : {1e-9, 1e-6, 1e-3, 0.1, 1.0, 3.0}) {
    for (int i = 0; i < 200; ++i) {
      Eigen::Vector3d w = RandomTangent<3>(rng, scale);
      if (w.norm() >= M_PI) continue;
      EXPECT_LT((SO3d::Exp(w).Log() - w).norm(), 1e-12 + 1e-12 * w.norm()) << w.transpose();
    }
  }
}

TEST(SO3, LogExpIsIdentityOnGroup) {
  std::mt19937 rng(2);
  for (int i = 0; i < 200; ++i) {
    const SO3d r = SO3d::Exp(RandomTangent<3>(rng, 3.0));
    EXPECT_LT((SO3d::Exp(r.Log()).Matrix() - r.Matrix()).norm(), 1e-12);
  }
}

TEST(SO3, LogNearPiStaysInRange) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 3).normalized();
  const SO3d r = SO3d::Exp(axis * (M_PI - 1e-9));
  EXPECT_NEAR(r.Log().norm(), M_PI - 1e-9, 1e-7);
  const SO3d r2 = SO3d::Exp(axis * (M_PI + 0.1));  // wraps to the other side
  EXPECT_NEAR(r2.Log().norm(), M_PI - 0.1, 1e-9);
  EXPECT_LT((SO3d::Exp(r2.Log()).Matrix() - r2.Matrix()).norm(), 1e-12);
}

TEST(SO3, MatchesRodriguesAndEigenAngleAxis) {
  const Eigen::Vector3d w(0.3, -0.2, 0.5);
  const Eigen::Matrix3d expected = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  EXPECT_LT((SO3d::Exp(w).Matrix() - expected).norm(), 1e-14);
}

TEST(SO3, RightJacobianMatchesNumeric) {
  std::mt19937 rng(3);
  for (double scale : {1e-7, 1e-3, 0.5, 2.0}) {
    for (int i = 0; i < 50; ++i) {
      const Eigen::Vector3d w = RandomTangent<3>(rng, scale);
      const Eigen::Matrix3d numeric = NumericRightJacobian<SO3d>(w);
      EXPECT_LT((SO3d::RightJacobian(w) - numeric).norm(), 1e-8) << w.transpose();
      EXPECT_LT((SO3d::RightJacobianInverse(w) * SO3d::RightJacobian(w) -
                 Eigen::Matrix3d::Identity())
                    .norm(),
                1e-10);
    }
  }
}

TEST(SO3, LeftJacobianDefinition) {
  // Exp(w + d) ~= Exp(Jl(w) d) * Exp(w)
  const Eigen::Vector3d w(0.4, 0.1, -0.7);
  const Eigen::Vector3d d(1e-6, -2e-6, 0.5e-6);
  const SO3d lhs = SO3d::Exp(w + d);
  const SO3d rhs = SO3d::Exp(SO3d::LeftJacobian(w) * d) * SO3d::Exp(w);
  EXPECT_LT((lhs.Inverse() * rhs).Log().norm(), 1e-11);
}

TEST(SO3, HatVeeAndAdjoint) {
  const Eigen::Vector3d a(1, 2, 3), b(-1, 0.5, 2);
  EXPECT_LT((SO3d::Hat(a) * b - a.cross(b)).norm(), 1e-15);
  EXPECT_EQ(SO3d::Vee(SO3d::Hat(a)), a);
  const SO3d r = SO3d::Exp(Eigen::Vector3d(0.2, 0.3, -0.1));
  // R Exp(w) R^T = Exp(Adj w)
  const SO3d lhs = r * SO3d::Exp(b * 0.1) * r.Inverse();
  EXPECT_LT((lhs.Log() - r.Adj() * b * 0.1).norm(), 1e-14);
}

TEST(SO3, InterpolationEndpointsAndMidpoint) {
  const SO3d a = SO3d::Exp(Eigen::Vector3d(0.1, 0.2, 0.3));
  const SO3d b = SO3d::Exp(Eigen::Vector3d(-0.4, 0.6, 1.2));
  EXPECT_LT((SO3d::Interpolate(a, b, 0.0).Matrix() - a.Matrix()).norm(), 1e-14);
  EXPECT_LT((SO3d::Interpolate(a, b, 1.0).Matrix() - b.Matrix()).norm(), 1e-12);
  const SO3d mid = SO3d::Interpolate(a, b, 0.5);
  // Equal geodesic distance to both ends.
  EXPECT_NEAR((a.Inverse() * mid).Angle(), (mid.Inverse() * b).Angle(), 1e-12);
}

TEST(SO3, FitToMatrixProjectsNoisyRotation) {
  const SO3d r = SO3d::Exp(Eigen::Vector3d(0.5, -0.3, 0.9));
  Eigen::Matrix3d noisy = r.Matrix();
  noisy(0, 1) += 1e-3;
  noisy(2, 0) -= 2e-3;
  const SO3d fit = SO3d::FitToMatrix(noisy);
  EXPECT_NEAR(fit.Matrix().determinant(), 1.0, 1e-12);
  EXPECT_LT((fit.Matrix() * fit.Matrix().transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_LT((fit.Inverse() * r).Angle(), 3e-3);
}

TEST(SO3, WorksWithCeresJets) {
  // Autodiff of Log(Exp(w0)^-1 Exp(w0 + d)) at d = 0 is Jr(w0).
  using Jet = ceres::Jet<double, 3>;
  const Eigen::Vector3d w0(0.3, -0.6, 0.2);
  Eigen::Matrix<Jet, 3, 1> d;
  for (int i = 0; i < 3; ++i) d(i) = Jet(0.0, i);
  const SO3<Jet> base = SO3d::Exp(w0).cast<Jet>();
  const Eigen::Matrix<Jet, 3, 1> out =
      (base.Inverse() * SO3<Jet>::Exp(w0.cast<Jet>() + d)).Log();
  Eigen::Matrix3d jac;
  for (int r = 0; r < 3; ++r) jac.row(r) = out(r).v.transpose();
  EXPECT_LT((jac - SO3d::RightJacobian(w0)).norm(), 1e-9);
}

}  // namespace
}  // namespace pkslam
