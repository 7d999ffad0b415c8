#include "evaluation/rpe.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/util/error.h"

namespace pkslam {
namespace {

std::vector<Eigen::Vector3d> PointsAlongX(const std::vector<double>& steps) {
  std::vector<Eigen::Vector3d> points = {Eigen::Vector3d::Zero()};
  for (const double step : steps) points.push_back(points.back() + Eigen::Vector3d(step, 0, 0));
  return points;
}

RpeOptions Options(double delta, RpeUnit unit, bool all_pairs) {
  RpeOptions options;
  options.delta = delta;
  options.unit = unit;
  options.all_pairs = all_pairs;
  return options;
}

using Pairs = std::vector<PosePairIndices>;

TEST(SelectRpePairs, FramesAllAndConsecutive) {
  const std::vector<Eigen::Vector3d> points(10, Eigen::Vector3d::Zero());
  EXPECT_EQ(SelectRpePairs(points, Options(3, RpeUnit::kFrames, true)),
            (Pairs{{0, 3}, {1, 4}, {2, 5}, {3, 6}, {4, 7}, {5, 8}, {6, 9}}));
  EXPECT_EQ(SelectRpePairs(points, Options(3, RpeUnit::kFrames, false)),
            (Pairs{{0, 3}, {3, 6}, {6, 9}}));
  EXPECT_TRUE(SelectRpePairs(points, Options(10, RpeUnit::kFrames, true)).empty());
}

TEST(SelectRpePairs, MetersConsecutiveFollowsEvosWalk) {
  // Path reaches 1 m at index 3 (1.2 m), then again 1.2 m later at 6 and 9; index 0 is not a
  // pair start in evo's walk.
  const std::vector<Eigen::Vector3d> points = PointsAlongX(std::vector<double>(10, 0.4));
  EXPECT_EQ(SelectRpePairs(points, Options(1.0, RpeUnit::kMeters, false)), (Pairs{{3, 6}, {6, 9}}));
}

TEST(SelectRpePairs, MetersAllPairsTakesThePathClosestToDelta) {
  const std::vector<Eigen::Vector3d> line = PointsAlongX(std::vector<double>(34, 0.1));
  RpeOptions options = Options(1.0, RpeUnit::kMeters, true);
  options.relative_tolerance = 0.05;
  const Pairs pairs = SelectRpePairs(line, options);
  ASSERT_EQ(pairs.size(), 25u);  // starts 0..24; from 25 on less than 0.95 m remain
  for (std::size_t i = 0; i < pairs.size(); ++i) EXPECT_EQ(pairs[i], PosePairIndices(i, i + 10));

  // Irregular steps: from 0 the path is 0.9 m at index 3 and 1.05 m at index 4 (closer).
  const std::vector<Eigen::Vector3d> uneven = PointsAlongX({0.3, 0.3, 0.3, 0.15, 0.3});
  const Pairs first = SelectRpePairs(uneven, Options(1.0, RpeUnit::kMeters, true));
  ASSERT_FALSE(first.empty());
  EXPECT_EQ(first.front(), PosePairIndices(0, 4));
  // Nothing within tolerance: no pairs.
  EXPECT_TRUE(SelectRpePairs(uneven, Options(5.0, RpeUnit::kMeters, true)).empty());
}

TEST(ComputeRpe, InvariantToAGlobalRigidTransform) {
  std::vector<SE3d> ref;
  for (int k = 0; k < 40; ++k) {
    ref.emplace_back(SO3d::Exp(Eigen::Vector3d(0.05 * k, 0.1, -0.02 * k)),
                     Eigen::Vector3d(std::sin(0.2 * k), 0.1 * k, std::cos(0.3 * k)));
  }
  const SE3d world_change(SO3d::Exp(Eigen::Vector3d(1.0, -2.0, 0.5)), Eigen::Vector3d(4, 5, 6));
  std::vector<SE3d> est;
  for (const SE3d& pose : ref) est.push_back(world_change * pose);
  for (const RpeUnit unit : {RpeUnit::kFrames, RpeUnit::kMeters}) {
    const RpeResult r =
        ComputeRpe(ref, est, Options(unit == RpeUnit::kFrames ? 5 : 0.5, unit, true));
    EXPECT_FALSE(r.pairs.empty());
    EXPECT_LT(r.translation_m.max, 1e-12);
    EXPECT_LT(r.rotation_deg.max, 1e-5);
  }
}

TEST(ComputeRpe, MeasuresKnownDriftPerStep) {
  // Reference: 1 m steps along x, turning 1 deg per step about z. Estimate: 1.1 m steps and
  // 1.5 deg per step. Every 1-frame relative motion is off by 0.1 m and 0.5 deg.
  std::vector<SE3d> ref;
  std::vector<SE3d> est;
  SE3d r;
  SE3d e;
  const double deg = M_PI / 180.0;
  for (int k = 0; k < 20; ++k) {
    ref.push_back(r);
    est.push_back(e);
    r = r * SE3d(SO3d::Exp(Eigen::Vector3d(0, 0, 1.0 * deg)), Eigen::Vector3d(1.0, 0, 0));
    e = e * SE3d(SO3d::Exp(Eigen::Vector3d(0, 0, 1.5 * deg)), Eigen::Vector3d(1.1, 0, 0));
  }
  const RpeResult one = ComputeRpe(ref, est, Options(1, RpeUnit::kFrames, true));
  ASSERT_EQ(one.pairs.size(), 19u);
  EXPECT_NEAR(one.translation_m.min, 0.1, 1e-12);
  EXPECT_NEAR(one.translation_m.max, 0.1, 1e-12);
  EXPECT_NEAR(one.rotation_deg.rmse, 0.5, 1e-9);
  // Two frames: rotation error 1 deg.
  EXPECT_NEAR(ComputeRpe(ref, est, Options(2, RpeUnit::kFrames, false)).rotation_deg.mean, 1.0,
              1e-9);
}

TEST(ComputeRpe, BadOptionsAndEmptySelectionsThrow) {
  const std::vector<SE3d> poses(5);
  EXPECT_THROW(ComputeRpe(poses, poses, Options(0, RpeUnit::kFrames, true)), OptionError);
  EXPECT_THROW(ComputeRpe(poses, poses, Options(1.5, RpeUnit::kFrames, true)), OptionError);
  EXPECT_THROW(ComputeRpe(poses, poses, Options(-1, RpeUnit::kMeters, true)), OptionError);
  EXPECT_THROW(ComputeRpe(poses, poses, Options(5, RpeUnit::kFrames, true)), OptionError);
  EXPECT_THROW(ComputeRpe(poses, poses, Options(1.0, RpeUnit::kMeters, true)), OptionError);
  EXPECT_THROW(ComputeRpe(poses, std::vector<SE3d>(4), Options(1, RpeUnit::kFrames, true)), Error);
  EXPECT_EQ(ParseRpeUnit("m"), RpeUnit::kMeters);
  EXPECT_EQ(ParseRpeUnit("frames"), RpeUnit::kFrames);
  EXPECT_THROW(ParseRpeUnit("s"), OptionError);
}

}  // namespace
}  // namespace pkslam
