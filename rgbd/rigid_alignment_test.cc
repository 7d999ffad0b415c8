#include "rgbd/rigid_alignment.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace pkslam::rgbd {
namespace {

std::vector<Eigen::Vector3d> RandomPoints(int n, unsigned seed, double flatten_z = 1.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) points.emplace_back(u(rng), u(rng), flatten_z * u(rng) + 2.0);
  return points;
}

std::vector<Eigen::Vector3d> Transform(const SE3d& t, const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& p : points) out.push_back(t * p);
  return out;
}

TEST(RigidAlignment, RecoversAKnownTransform) {
  const SE3d truth(SO3d::Exp(Eigen::Vector3d(0.3, -0.2, 0.9)), Eigen::Vector3d(0.5, -1.0, 0.25));
  const auto source = RandomPoints(20, 1);
  const auto estimate = AlignRigid(source, Transform(truth, source));
  ASSERT_TRUE(estimate.has_value());
  EXPECT_LT((estimate->Matrix() - truth.Matrix()).norm(), 1e-9);
}

TEST(RigidAlignment, CoplanarPointsGiveAProperRotation) {
  // Noise-free coplanar points: H has a zero singular value and the plain V U^T can be a
  // reflection; the fix must return the true rotation with det +1.
  const SE3d truth(SO3d::Exp(Eigen::Vector3d(-0.4, 0.7, 0.1)), Eigen::Vector3d(0.1, 0.2, 0.3));
  const auto source = RandomPoints(10, 2, 0.0);  // all at z = 2
  const auto estimate = AlignRigid(source, Transform(truth, source));
  ASSERT_TRUE(estimate.has_value());
  EXPECT_NEAR(estimate->RotationMatrix().determinant(), 1.0, 1e-12);
  EXPECT_LT((estimate->Matrix() - truth.Matrix()).norm(), 1e-9);
}

TEST(RigidAlignment, MirroredDataIsFittedByARotationNotAReflection) {
  const auto source = RandomPoints(30, 3);
  std::vector<Eigen::Vector3d> target;
  for (const auto& p : source) target.emplace_back(-p.x(), p.y(), p.z());  // a mirror image
  // The unconstrained orthogonal solution is the mirror (det -1).
  Eigen::Vector3d ms = Eigen::Vector3d::Zero(), mt = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < source.size(); ++i) {
    ms += source[i];
    mt += target[i];
  }
  ms /= source.size();
  mt /= source.size();
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < source.size(); ++i)
    h += (source[i] - ms) * (target[i] - mt).transpose();
  const Eigen::Matrix3d r = RotationFromCrossCovariance(h);
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  EXPECT_LT((r * r.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  const auto estimate = AlignRigid(source, target);
  ASSERT_TRUE(estimate.has_value());
  EXPECT_NEAR(estimate->RotationMatrix().determinant(), 1.0, 1e-12);
}

TEST(RigidAlignment, DegenerateInputsHaveNoSolution) {
  const std::vector<Eigen::Vector3d> two = {{0, 0, 1}, {1, 0, 1}};
  EXPECT_FALSE(AlignRigid(two, two).has_value());
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 5; ++i) line.emplace_back(i, 2.0 * i, 1);
  EXPECT_FALSE(AlignRigid(line, line).has_value());
}

TEST(RigidAlignment, IndexedSubsetUsesOnlyThosePairs) {
  const SE3d truth(SO3d::Exp(Eigen::Vector3d(0.1, 0.2, 0.3)), Eigen::Vector3d(1, 2, 3));
  const auto source = RandomPoints(10, 4);
  auto target = Transform(truth, source);
  target[9] += Eigen::Vector3d(5, 5, 5);  // an outlier left out by the indices
  const std::vector<int> indices = {0, 1, 2, 3, 4, 5, 6, 7, 8};
  const auto estimate = AlignRigid(source, target, indices);
  ASSERT_TRUE(estimate.has_value());
  EXPECT_LT((estimate->Matrix() - truth.Matrix()).norm(), 1e-9);
}

}  // namespace
}  // namespace pkslam::rgbd
