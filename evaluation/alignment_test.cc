#include "evaluation/alignment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/util/error.h"

namespace pkslam {
namespace {

constexpr double kDeg = M_PI / 180.0;

std::vector<Eigen::Vector3d> RandomPoints(std::size_t n, std::mt19937& rng,
                                          const Eigen::Vector3d& spread) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (std::size_t i = 0; i < n; ++i) {
    points.emplace_back(spread.x() * normal(rng), spread.y() * normal(rng),
                        spread.z() * normal(rng));
  }
  return points;
}

// t * p for each point, plus isotropic Gaussian noise when noise_sigma > 0.
std::vector<Eigen::Vector3d> Transform(const Sim3d& t, const std::vector<Eigen::Vector3d>& in,
                                       double noise_sigma, std::mt19937& rng) {
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector3d& p : in) out.push_back(t * p);
  if (noise_sigma > 0.0) {
    std::normal_distribution<double> noise(0.0, noise_sigma);
    for (Eigen::Vector3d& p : out) p += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  }
  return out;
}

double RotationError(const SO3d& a, const SO3d& b) { return (a.Inverse() * b).Angle(); }

TEST(UmeyamaAlignment, RecoversAKnownSim3FromNoisyPoints) {
  std::mt19937 rng(7);
  const std::vector<Eigen::Vector3d> est = RandomPoints(500, rng, Eigen::Vector3d(4, 3, 2));
  const Sim3d truth(2.5, SO3d::Exp(Eigen::Vector3d(0.4, -1.1, 2.0)), Eigen::Vector3d(5, -3, 8));
  const std::vector<Eigen::Vector3d> ref = Transform(truth, est, 0.01, rng);
  const Sim3d fit = UmeyamaAlignment(est, ref, /*with_scale=*/true);
  EXPECT_NEAR(fit.scale(), 2.5, 2e-3);
  EXPECT_LT(RotationError(fit.so3(), truth.so3()), 0.05 * kDeg);
  EXPECT_LT((fit.translation() - truth.translation()).norm(), 5e-3);
  // Noise-free: exact to rounding.
  const Sim3d exact = UmeyamaAlignment(est, Transform(truth, est, 0.0, rng), true);
  EXPECT_NEAR(exact.scale(), 2.5, 1e-12);
  EXPECT_LT(RotationError(exact.so3(), truth.so3()), 1e-10);
  EXPECT_LT((exact.translation() - truth.translation()).norm(), 1e-10);
}

TEST(UmeyamaAlignment, Se3KeepsScaleOne) {
  std::mt19937 rng(11);
  const std::vector<Eigen::Vector3d> est = RandomPoints(200, rng, Eigen::Vector3d(1, 1, 1));
  const Sim3d rigid(1.0, SO3d::Exp(Eigen::Vector3d(-0.3, 0.2, 0.9)), Eigen::Vector3d(1, 2, 3));
  const Sim3d fit = AlignPositions(est, Transform(rigid, est, 0.005, rng), AlignmentMethod::kSE3);
  EXPECT_EQ(fit.scale(), 1.0);
  EXPECT_LT(RotationError(fit.so3(), rigid.so3()), 0.1 * kDeg);
  EXPECT_LT((fit.translation() - rigid.translation()).norm(), 2e-3);
}

TEST(UmeyamaAlignment, NeverReturnsAReflection) {
  // The reference is the mirror image (x -> -x) of the estimate. The best reflection would fit
  // exactly; the best rotation (spread 3 > 2 > 1 along x, y, z) turns by pi about y, flipping
  // the axis of least spread. Without the determinant fix the SVD would give diag(-1, 1, 1).
  std::mt19937 rng(3);
  const std::vector<Eigen::Vector3d> est = RandomPoints(2000, rng, Eigen::Vector3d(3, 2, 1));
  std::vector<Eigen::Vector3d> ref;
  for (const Eigen::Vector3d& p : est) ref.emplace_back(-p.x(), p.y(), p.z());
  const Eigen::Matrix3d r = UmeyamaAlignment(est, ref, false).RotationMatrix();
  EXPECT_NEAR(r.determinant(), 1.0, 1e-9);
  EXPECT_LT((r - Eigen::Vector3d(-1, 1, -1).asDiagonal().toDenseMatrix()).norm(), 0.05) << r;
}

TEST(UmeyamaAlignment, PlanarPointsGiveTheTrueRotation) {
  // Coplanar points: the smallest singular value is zero and the SVD's third directions have
  // arbitrary signs; the determinant fix must still pick the proper rotation.
  std::mt19937 rng(5);
  const std::vector<Eigen::Vector3d> est = RandomPoints(100, rng, Eigen::Vector3d(2, 1, 0));
  for (const double angle : {0.3, 1.7, -2.9}) {
    const Sim3d truth(1.0, SO3d::Exp(angle * Eigen::Vector3d(1, 2, -0.5).normalized()),
                      Eigen::Vector3d(0.5, 0, -1));
    const Sim3d fit = UmeyamaAlignment(est, Transform(truth, est, 0.0, rng), false);
    EXPECT_LT(RotationError(fit.so3(), truth.so3()), 1e-9) << angle;
  }
}

TEST(PositionYawAlignment, RecoversYawAndTranslation) {
  std::mt19937 rng(13);
  const std::vector<Eigen::Vector3d> est = RandomPoints(300, rng, Eigen::Vector3d(5, 5, 1));
  for (const double yaw : {0.0, 0.5, 2.8, -3.0, -1.2}) {
    const Sim3d truth(1.0, SO3d::Exp(Eigen::Vector3d(0, 0, yaw)), Eigen::Vector3d(-2, 4, 0.3));
    const Sim3d exact = PositionYawAlignment(est, Transform(truth, est, 0.0, rng));
    EXPECT_LT(RotationError(exact.so3(), truth.so3()), 1e-10) << yaw;
    EXPECT_LT((exact.translation() - truth.translation()).norm(), 1e-9) << yaw;
    const Sim3d noisy = PositionYawAlignment(est, Transform(truth, est, 0.02, rng));
    EXPECT_LT(RotationError(noisy.so3(), truth.so3()), 0.05 * kDeg) << yaw;
    EXPECT_LT((noisy.translation() - truth.translation()).norm(), 5e-3) << yaw;
    EXPECT_EQ(noisy.scale(), 1.0);
  }
}

TEST(PositionYawAlignment, IgnoresRollAndPitch) {
  // The true transform also tilts by a few degrees; posyaw may only rotate about z.
  std::mt19937 rng(17);
  const std::vector<Eigen::Vector3d> est = RandomPoints(300, rng, Eigen::Vector3d(5, 4, 0.5));
  const SO3d yaw = SO3d::Exp(Eigen::Vector3d(0, 0, 1.0));
  const SO3d tilt = SO3d::Exp(Eigen::Vector3d(2.0 * kDeg, -3.0 * kDeg, 0));
  const Sim3d truth(1.0, yaw * tilt, Eigen::Vector3d(1, 2, 3));
  const std::vector<Eigen::Vector3d> ref = Transform(truth, est, 0.0, rng);
  const Sim3d fit = PositionYawAlignment(est, ref);
  const Eigen::Vector3d axis_image = fit.so3() * Eigen::Vector3d::UnitZ();
  EXPECT_LT((axis_image - Eigen::Vector3d::UnitZ()).norm(), 1e-12);  // z stays z: pure yaw
  EXPECT_LT(RotationError(fit.so3(), yaw), 1.0 * kDeg);              // close to the true yaw
  // SE3 explains the tilt that posyaw may not.
  const Sim3d se3 = AlignPositions(est, ref, AlignmentMethod::kSE3);
  EXPECT_LT(RotationError(se3.so3(), truth.so3()), 1e-9);
  EXPECT_GT(RotationError(fit.so3(), truth.so3()), 2.0 * kDeg);
}

TEST(AlignPositions, NoneIsIdentityAndBadInputsThrow) {
  const std::vector<Eigen::Vector3d> a = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<Eigen::Vector3d> b = {{5, 5, 5}, {6, 5, 5}, {5, 6, 5}};
  const Sim3d none = AlignPositions(a, b, AlignmentMethod::kNone);
  EXPECT_EQ(none.scale(), 1.0);
  EXPECT_EQ(none.translation(), Eigen::Vector3d::Zero());
  EXPECT_LT(
      (AlignPositions(a, b, AlignmentMethod::kSE3).translation() - Eigen::Vector3d(5, 5, 5)).norm(),
      1e-12);
  EXPECT_THROW(AlignPositions(a, {b[0], b[1]}, AlignmentMethod::kSE3), Error);  // sizes differ
  EXPECT_THROW(AlignPositions({a[0], a[1]}, {b[0], b[1]}, AlignmentMethod::kSim3), Error);
  EXPECT_NO_THROW(AlignPositions({a[0], a[1]}, {b[0], b[1]}, AlignmentMethod::kPosYaw));
  const std::vector<Eigen::Vector3d> same(3, Eigen::Vector3d(1, 1, 1));
  EXPECT_THROW(AlignPositions(same, b, AlignmentMethod::kSim3), Error);  // scale undefined
}

TEST(AlignmentMethodNames, ParseAndPrint) {
  for (const auto m : {AlignmentMethod::kNone, AlignmentMethod::kSE3, AlignmentMethod::kSim3,
                       AlignmentMethod::kPosYaw}) {
    EXPECT_EQ(ParseAlignmentMethod(AlignmentMethodName(m)), m);
  }
  EXPECT_THROW(ParseAlignmentMethod("SE3"), OptionError);
  EXPECT_THROW(ParseAlignmentMethod("scale"), OptionError);
}

}  // namespace
}  // namespace pkslam
