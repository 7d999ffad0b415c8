#include <gtest/gtest.h>

#include <unsupported/Eigen/MatrixFunctions>

#include "core/geometry/lie_test_utils.h"
#include "core/geometry/se3.h"
#include "core/geometry/sim3.h"

namespace pkslam {
namespace {

using testing::NumericRightJacobian;
using testing::RandomTangent;

template <typename Group>
class LieGroupTest : public ::testing::Test {};

using Groups = ::testing::Types<SE3d, Sim3d>;
TYPED_TEST_SUITE(LieGroupTest, Groups);

TYPED_TEST(LieGroupTest, ExpMatchesMatrixExponential) {
  using G = TypeParam;
  std::mt19937 rng(4);
  for (double scale : {1e-8, 1e-4, 0.3, 1.5}) {
    for (int i = 0; i < 50; ++i) {
      const auto x = RandomTangent<G::kDof>(rng, scale);
      const Eigen::Matrix4d expected = G::Hat(x).exp();
      EXPECT_LT((G::Exp(x).Matrix() - expected).norm(), 1e-11) << x.transpose();
    }
  }
}

TYPED_TEST(LieGroupTest, ExpLogRoundTrip) {
  using G = TypeParam;
  std::mt19937 rng(5);
  for (double scale : {1e-9, 1e-5, 0.1, 1.0, 1.7}) {
    for (int i = 0; i < 100; ++i) {
      const auto x = RandomTangent<G::kDof>(rng, scale);
      if (x.template segment<3>(3).norm() >= M_PI) continue;
      EXPECT_LT((G::Exp(x).Log() - x).norm(), 1e-10) << x.transpose();
    }
  }
}

TYPED_TEST(LieGroupTest, InverseAndComposition) {
  using G = TypeParam;
  std::mt19937 rng(6);
  const G a = G::Exp(RandomTangent<G::kDof>(rng, 1.0));
  const G b = G::Exp(RandomTangent<G::kDof>(rng, 1.0));
  EXPECT_LT(((a * a.Inverse()).Matrix() - Eigen::Matrix4d::Identity()).norm(), 1e-12);
  EXPECT_LT(((a * b).Matrix() - a.Matrix() * b.Matrix()).norm(), 1e-12);
  const Eigen::Vector3d p(0.3, -2.0, 5.0);
  const Eigen::Vector4d ph = a.Matrix() * p.homogeneous();
  EXPECT_LT((a * p - ph.head<3>()).norm(), 1e-12);
}

TYPED_TEST(LieGroupTest, AdjointConjugation) {
  using G = TypeParam;
  std::mt19937 rng(7);
  const G t = G::Exp(RandomTangent<G::kDof>(rng, 1.0));
  const auto x = RandomTangent<G::kDof>(rng, 0.2);
  const G lhs = t * G::Exp(x) * t.Inverse();
  EXPECT_LT((lhs.Log() - t.Adj() * x).norm(), 1e-10);
}

TYPED_TEST(LieGroupTest, RightJacobianMatchesNumeric) {
  using G = TypeParam;
  std::mt19937 rng(8);
  for (double scale : {1e-6, 0.1, 1.0}) {
    for (int i = 0; i < 20; ++i) {
      const auto x = RandomTangent<G::kDof>(rng, scale);
      const auto numeric = NumericRightJacobian<G>(x);
      EXPECT_LT((G::RightJacobian(x) - numeric).norm(), 1e-7) << x.transpose();
      EXPECT_LT((G::RightJacobianInverse(x) * numeric).eval().diagonal().sum() - G::kDof, 1e-6);
    }
  }
}

TYPED_TEST(LieGroupTest, InterpolationEndpoints) {
  using G = TypeParam;
  std::mt19937 rng(9);
  const G a = G::Exp(RandomTangent<G::kDof>(rng, 0.8));
  const G b = G::Exp(RandomTangent<G::kDof>(rng, 0.8));
  EXPECT_LT((G::Interpolate(a, b, 0.0).Matrix() - a.Matrix()).norm(), 1e-12);
  EXPECT_LT((G::Interpolate(a, b, 1.0).Matrix() - b.Matrix()).norm(), 1e-10);
}

TEST(SE3, AdjointOrderingIsTranslationFirst) {
  // A pure translation twist stays a translation under a pure rotation.
  const SE3d r(SO3d::Exp(Eigen::Vector3d(0, 0, M_PI / 2)), Eigen::Vector3d::Zero());
  Eigen::Matrix<double, 6, 1> x = Eigen::Matrix<double, 6, 1>::Zero();
  x(0) = 1.0;
  const Eigen::Matrix<double, 6, 1> y = r.Adj() * x;
  EXPECT_NEAR(y(1), 1.0, 1e-12);
  EXPECT_NEAR(y.tail<3>().norm(), 0.0, 1e-12);
}

TEST(SE3, MatrixConstructorRoundTrip) {
  const SE3d t = SE3d::Exp((Eigen::Matrix<double, 6, 1>() << 1, 2, 3, 0.1, 0.2, 0.3).finished());
  const SE3d u(t.Matrix());
  EXPECT_LT((u.Matrix() - t.Matrix()).norm(), 1e-14);
}

TEST(Sim3, ScaleActsOnPointsAndComposes) {
  const Sim3d s(2.0, SO3d::Exp(Eigen::Vector3d(0, 0, 0.5)), Eigen::Vector3d(1, 0, 0));
  EXPECT_NEAR((s * Eigen::Vector3d(1, 0, 0)).norm(), (Eigen::Vector3d(1, 0, 0) +
              2.0 * SO3d::Exp(Eigen::Vector3d(0, 0, 0.5)).Matrix().col(0)).norm(), 1e-14);
  EXPECT_NEAR((s * s.Inverse()).scale(), 1.0, 1e-15);
  EXPECT_NEAR(s.Log()(6), std::log(2.0), 1e-15);
  const SE3d rigid = s.ToSE3ScaledTranslation();
  EXPECT_LT((rigid.translation() - Eigen::Vector3d(0.5, 0, 0)).norm(), 1e-15);
}

TEST(Sim3, LargeScaleAndRotationExp) {
  // W in closed form (theta >= 1) and series form (theta < 1) agree at the switch.
  for (double sigma : {-2.0, -1e-7, 0.0, 1e-7, 0.7, 3.0}) {
    const Eigen::Vector3d axis = Eigen::Vector3d(0.2, -0.5, 0.8).normalized();
    const Eigen::Matrix3d below = Sim3d::W(axis * (1 - 1e-9), sigma);
    const Eigen::Matrix3d above = Sim3d::W(axis * (1 + 1e-9), sigma);
    EXPECT_LT((below - above).norm(), 1e-7) << sigma;
  }
}

}  // namespace
}  // namespace pkslam
