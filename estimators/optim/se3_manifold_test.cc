#include "estimators/optim/se3_manifold.h"

#include <gtest/gtest.h>

#include <random>

#include "core/geometry/lie_test_utils.h"

namespace pkslam {
namespace {

using testing::RandomTangent;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Block = Eigen::Matrix<double, 7, 1>;

Block RandomPoseBlock(std::mt19937& rng) {
  Block x;
  PoseToBlock(SE3d::Exp(RandomTangent<6>(rng, 2.0)), x.data());
  return x;
}

TEST(SE3LeftManifold, BlockRoundTrip) {
  std::mt19937 rng(1);
  const SE3d pose = SE3d::Exp(RandomTangent<6>(rng, 2.0));
  Block x;
  PoseToBlock(pose, x.data());
  EXPECT_LT((PoseFromBlock(x.data()).Matrix() - pose.Matrix()).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(x(3), pose.quaternion().w());
  EXPECT_DOUBLE_EQ(x(6), pose.translation().z());
}

TEST(SE3LeftManifold, PlusIsLeftPerturbation) {
  std::mt19937 rng(2);
  const SE3LeftManifold manifold;
  for (int i = 0; i < 50; ++i) {
    const Block x = RandomPoseBlock(rng);
    const Vec6 delta = RandomTangent<6>(rng, 0.5);
    Block y;
    ASSERT_TRUE(manifold.Plus(x.data(), delta.data(), y.data()));
    const Eigen::Matrix4d expected = (SE3d::Exp(delta) * PoseFromBlock(x.data())).Matrix();
    EXPECT_LT((PoseFromBlock(y.data()).Matrix() - expected).norm(), 1e-12);
    // Not the right perturbation (would differ for a non-identity pose).
    const Eigen::Matrix4d right = (PoseFromBlock(x.data()) * SE3d::Exp(delta)).Matrix();
    EXPECT_GT((PoseFromBlock(y.data()).Matrix() - right).norm(), 1e-6);
    EXPECT_NEAR(y.head<4>().norm(), 1.0, 1e-14);
  }
}

TEST(SE3LeftManifold, PlusZeroIsIdentity) {
  std::mt19937 rng(3);
  const SE3LeftManifold manifold;
  const Block x = RandomPoseBlock(rng);
  Block y;
  const Vec6 zero = Vec6::Zero();
  ASSERT_TRUE(manifold.Plus(x.data(), zero.data(), y.data()));
  // Same rotation (q or -q) and translation.
  EXPECT_LT((PoseFromBlock(y.data()).Matrix() - PoseFromBlock(x.data()).Matrix()).norm(), 1e-14);
}

TEST(SE3LeftManifold, MinusInvertsPlus) {
  std::mt19937 rng(4);
  const SE3LeftManifold manifold;
  for (double scale : {1e-7, 1e-3, 0.3, 1.2}) {
    for (int i = 0; i < 50; ++i) {
      const Block x = RandomPoseBlock(rng);
      const Vec6 delta = RandomTangent<6>(rng, scale);
      Block y;
      Vec6 back;
      ASSERT_TRUE(manifold.Plus(x.data(), delta.data(), y.data()));
      ASSERT_TRUE(manifold.Minus(y.data(), x.data(), back.data()));
      EXPECT_LT((back - delta).norm(), 1e-10 * std::max(1.0, delta.norm())) << scale;
    }
  }
}

TEST(SE3LeftManifold, PlusInvertsMinus) {
  std::mt19937 rng(5);
  const SE3LeftManifold manifold;
  for (int i = 0; i < 50; ++i) {
    const Block x = RandomPoseBlock(rng);
    const Block y = RandomPoseBlock(rng);
    Vec6 d;
    Block z;
    ASSERT_TRUE(manifold.Minus(y.data(), x.data(), d.data()));
    ASSERT_TRUE(manifold.Plus(x.data(), d.data(), z.data()));
    EXPECT_LT((PoseFromBlock(z.data()).Matrix() - PoseFromBlock(y.data()).Matrix()).norm(), 1e-10);
  }
}

TEST(SE3LeftManifold, MinusOfSelfIsZero) {
  std::mt19937 rng(6);
  const SE3LeftManifold manifold;
  const Block x = RandomPoseBlock(rng);
  Vec6 d;
  ASSERT_TRUE(manifold.Minus(x.data(), x.data(), d.data()));
  EXPECT_LT(d.norm(), 1e-14);
}

TEST(SE3LeftManifold, JacobiansFollowTheI6Convention) {
  std::mt19937 rng(7);
  const SE3LeftManifold manifold;
  const Block x = RandomPoseBlock(rng);
  Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus;
  Eigen::Matrix<double, 6, 7, Eigen::RowMajor> minus;
  ASSERT_TRUE(manifold.PlusJacobian(x.data(), plus.data()));
  ASSERT_TRUE(manifold.MinusJacobian(x.data(), minus.data()));
  Eigen::Matrix<double, 7, 6> expected = Eigen::Matrix<double, 7, 6>::Zero();
  expected.topRows<6>().setIdentity();
  EXPECT_TRUE(plus == expected);
  // Ceres requires MinusJacobian * PlusJacobian = I.
  EXPECT_TRUE((minus * plus).isIdentity(0.0));

  // RightMultiplyByPlusJacobian agrees with the explicit product.
  Eigen::Matrix<double, 3, 7, Eigen::RowMajor> ambient;
  for (int i = 0; i < ambient.size(); ++i) ambient.data()[i] = i + 1.0;
  Eigen::Matrix<double, 3, 6, Eigen::RowMajor> tangent;
  ASSERT_TRUE(manifold.RightMultiplyByPlusJacobian(x.data(), 3, ambient.data(), tangent.data()));
  const Eigen::Matrix<double, 3, 6> product = ambient * plus;
  EXPECT_TRUE(tangent == product);
}

// Holding rho: the block only turns, so the parent's origin in the child frame stays put.
TEST(SE3LeftSubsetManifold, HeldTranslationKeepsTheInverseTranslation) {
  std::mt19937 rng(11);
  const SE3LeftSubsetManifold manifold({true, true, true, false, false, false});
  ASSERT_EQ(manifold.TangentSize(), 3);
  const Block x = RandomPoseBlock(rng);
  const Eigen::Vector3d delta = RandomTangent<3>(rng, 0.3);
  Block moved;
  ASSERT_TRUE(manifold.Plus(x.data(), delta.data(), moved.data()));
  const SE3d before = PoseFromBlock(x.data());
  const SE3d after = PoseFromBlock(moved.data());
  EXPECT_LT((after.Inverse().translation() - before.Inverse().translation()).norm(), 1e-12);
  // The rotation moved by exactly the free part, as SE3LeftManifold would with rho = 0.
  Vec6 full = Vec6::Zero();
  full.tail<3>() = delta;
  EXPECT_LT(((after * before.Inverse()).Log() - full).norm(), 1e-12);
  Eigen::Vector3d back;
  ASSERT_TRUE(manifold.Minus(moved.data(), x.data(), back.data()));
  EXPECT_LT((back - delta).norm(), 1e-12);
}

TEST(SE3LeftSubsetManifold, JacobiansSelectTheFreeAxes) {
  std::mt19937 rng(13);
  // The stereo extrinsic's freedom: rotation about y and z only.
  const SE3LeftSubsetManifold manifold({true, true, true, true, false, false});
  const int k = manifold.TangentSize();
  ASSERT_EQ(k, 2);
  const Block x = RandomPoseBlock(rng);
  Eigen::Matrix<double, 7, Eigen::Dynamic, Eigen::RowMajor> plus(7, k);
  Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor> minus(k, 7);
  ASSERT_TRUE(manifold.PlusJacobian(x.data(), plus.data()));
  ASSERT_TRUE(manifold.MinusJacobian(x.data(), minus.data()));
  EXPECT_TRUE((minus * plus).isIdentity(0.0));
  const Eigen::MatrixXd e = manifold.Expansion();
  EXPECT_TRUE(plus.topRows<6>() == e);
  EXPECT_EQ(e(4, 0), 1.0);
  EXPECT_EQ(e(5, 1), 1.0);
  Eigen::Matrix<double, 3, 7, Eigen::RowMajor> ambient;
  for (int i = 0; i < ambient.size(); ++i) ambient.data()[i] = i + 1.0;
  Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor> tangent(3, k);
  ASSERT_TRUE(manifold.RightMultiplyByPlusJacobian(x.data(), 3, ambient.data(), tangent.data()));
  EXPECT_TRUE(tangent == ambient * plus);
}

TEST(SE3LeftSubsetManifold, RefusesToHoldEveryAxis) {
  EXPECT_ANY_THROW(SE3LeftSubsetManifold({true, true, true, true, true, true}));
}

}  // namespace
}  // namespace pkslam
