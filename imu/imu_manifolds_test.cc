#include "imu/imu_manifolds.h"

#include <gtest/gtest.h>

#include <random>

#include "core/geometry/lie_test_utils.h"

namespace pkslam {
namespace {

using testing::RandomTangent;
using Vec3 = Eigen::Vector3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using BodyPose7 = Eigen::Matrix<double, 7, 1>;

TEST(BodyPoseManifold, BlockLayoutMatchesCoreOptim) {
  // (qx, qy, qz, qw, tx, ty, tz): the layout of estimators/optim's pose blocks.
  const SE3d pose(SO3d::Exp(Vec3(0.1, 0.2, 0.3)), Vec3(1, 2, 3));
  BodyPose7 x;
  BodyPoseToBlock(pose, x.data());
  EXPECT_DOUBLE_EQ(x(0), pose.quaternion().x());
  EXPECT_DOUBLE_EQ(x(3), pose.quaternion().w());
  EXPECT_DOUBLE_EQ(x(4), 1.0);
  EXPECT_DOUBLE_EQ(x(6), 3.0);
  EXPECT_LT((BodyPoseFromBlock(x.data()).Matrix() - pose.Matrix()).norm(), 1e-15);
}

TEST(BodyPoseManifold, PlusIsRightPerturbationAndMinusInvertsIt) {
  std::mt19937 rng(1);
  const BodyPoseManifold manifold;
  for (int i = 0; i < 50; ++i) {
    BodyPose7 x;
    BodyPoseToBlock(SE3d::Exp(RandomTangent<6>(rng, 2.0)), x.data());
    const Vec6 delta = RandomTangent<6>(rng, 0.5);
    BodyPose7 y;
    ASSERT_TRUE(manifold.Plus(x.data(), delta.data(), y.data()));
    const SE3d expected = BodyPoseFromBlock(x.data()) * SE3d::Exp(delta);
    EXPECT_LT((BodyPoseFromBlock(y.data()).Matrix() - expected.Matrix()).norm(), 1e-12);
    // rho moves the position along the body axes.
    const Vec3 body_x = BodyPoseFromBlock(x.data()).so3() * Vec3::UnitX();
    Vec6 along_x = Vec6::Zero();
    along_x(0) = 1e-3;
    BodyPose7 z;
    manifold.Plus(x.data(), along_x.data(), z.data());
    EXPECT_LT(((z.tail<3>() - x.tail<3>()) / 1e-3 - body_x).norm(), 1e-9);
    Vec6 back;
    ASSERT_TRUE(manifold.Minus(y.data(), x.data(), back.data()));
    EXPECT_LT((back - delta).norm(), 1e-10);
  }
}

TEST(BodyPoseManifold, JacobiansAreTheIdentityPadding) {
  const BodyPoseManifold manifold;
  BodyPose7 x;
  BodyPoseToBlock(SE3d(), x.data());
  Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus;
  manifold.PlusJacobian(x.data(), plus.data());
  EXPECT_TRUE(plus.topRows<6>().isIdentity());
  EXPECT_TRUE(plus.row(6).isZero());
  Eigen::Matrix<double, 6, 7, Eigen::RowMajor> minus;
  manifold.MinusJacobian(x.data(), minus.data());
  EXPECT_TRUE((minus * plus).isIdentity());
  Eigen::Matrix<double, 2, 7, Eigen::RowMajor> ambient;
  ambient.setRandom();
  Eigen::Matrix<double, 2, 6, Eigen::RowMajor> tangent;
  manifold.RightMultiplyByPlusJacobian(x.data(), 2, ambient.data(), tangent.data());
  EXPECT_EQ(tangent, ambient.leftCols<6>());
}

TEST(GravityDirectionManifold, PlusTiltsGravityAndMinusInvertsIt) {
  std::mt19937 rng(2);
  const GravityDirectionManifold manifold;
  for (int i = 0; i < 50; ++i) {
    double x[4], y[4];
    GravityRotationToBlock(SO3d::Exp(RandomTangent<3>(rng, 2.0)), x);
    const Eigen::Vector2d delta = RandomTangent<2>(rng, 0.5);
    ASSERT_TRUE(manifold.Plus(x, delta.data(), y));
    const SO3d expected = GravityRotationFromBlock(x) * SO3d::Exp(Vec3(delta.x(), delta.y(), 0.0));
    EXPECT_LT((GravityRotationFromBlock(y).Matrix() - expected.Matrix()).norm(), 1e-12);
    // The gravity direction moves by the tangent's norm (small-angle), whatever the yaw.
    const Vec3 g0 = GravityRotationFromBlock(x) * Vec3(0, 0, -1);
    const Vec3 g1 = GravityRotationFromBlock(y) * Vec3(0, 0, -1);
    EXPECT_NEAR(std::acos(std::clamp(g0.dot(g1), -1.0, 1.0)), delta.norm(), 1e-9);
    Eigen::Vector2d back;
    ASSERT_TRUE(manifold.Minus(y, x, back.data()));
    EXPECT_LT((back - delta).norm(), 1e-10);
  }
}

TEST(GravityRotationFromDirection, MapsDownToTheDirection) {
  std::mt19937 rng(3);
  for (int i = 0; i < 20; ++i) {
    const Vec3 dir = RandomTangent<3>(rng, 1.0);
    EXPECT_LT((GravityRotationFromDirection(dir) * Vec3(0, 0, -1) - dir.normalized()).norm(),
              1e-12);
  }
  EXPECT_LT(
      (GravityRotationFromDirection(Vec3(0, 0, -3)).Matrix() - Eigen::Matrix3d::Identity()).norm(),
      1e-15);
  EXPECT_LT((GravityRotationFromDirection(Vec3(0, 0, 2)) * Vec3(0, 0, -1) - Vec3(0, 0, 1)).norm(),
            1e-12);
}

}  // namespace
}  // namespace pkslam
