#include "evaluation/segment_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/util/error.h"

namespace pkslam {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
using Pairs = std::vector<PosePairIndices>;

// Poses along x, 0.25 m apart (exact in binary, so the tolerance edges are exact too).
std::vector<SE3d> EvenLine(std::size_t count, double step = 0.25) {
  std::vector<SE3d> poses;
  for (std::size_t k = 0; k < count; ++k) {
    poses.emplace_back(SO3d(), Eigen::Vector3d(step * static_cast<double>(k), 0, 0));
  }
  return poses;
}

SO3d AboutAxis(const Eigen::Vector3d& axis, double deg) {
  return SO3d::Exp(axis.normalized() * deg * kDegToRad);
}

SegmentErrorOptions Lengths(std::vector<double> lengths) {
  SegmentErrorOptions options;
  options.lengths_m = std::move(lengths);
  return options;
}

// rpg's rule as written there: for each start, scan every later pose, keep the first with the
// smallest |D_j - D_i - L| below the tolerance.
Pairs BruteForcePairs(const std::vector<double>& d, double length, double fraction) {
  Pairs pairs;
  for (std::size_t i = 0; i < d.size(); ++i) {
    std::size_t best = d.size();
    double error = fraction * length;
    for (std::size_t j = i; j < d.size(); ++j) {
      if (std::abs(d[j] - (d[i] + length)) < error) {
        best = j;
        error = std::abs(d[j] - (d[i] + length));
      }
    }
    if (best < d.size()) pairs.emplace_back(i, best);
  }
  return pairs;
}

TEST(SegmentErrors, PairsSpanTheLengthAlongTheReferencePath) {
  // 9 poses, 2 m: each start with 1 m of path left pairs with the pose 4 steps on; from 1.25 m
  // the nearest end (2.0 m) misses 2.25 m by 0.25 > 0.2 m.
  const std::vector<SE3d> line = EvenLine(9);
  const auto segments = ComputeSegmentErrors(line, line, Lengths({1.0}));
  ASSERT_EQ(segments.size(), 1u);
  EXPECT_EQ(segments[0].pairs, (Pairs{{0, 4}, {1, 5}, {2, 6}, {3, 7}, {4, 8}}));
  for (const double e : segments[0].translation_m) EXPECT_EQ(e, 0.0);
}

TEST(SegmentErrors, StandingStillAndTiesTakeTheFirstPose) {
  EXPECT_EQ(SelectSegmentPairs({0, 0, 0, 1, 1, 2}, 1.0, 0.2),
            (Pairs{{0, 3}, {1, 3}, {2, 3}, {3, 5}, {4, 5}}));
  // 0.75 and 1.25 miss 1.0 by the same 0.25: the earlier pose wins, as in rpg's scan. From
  // 0.75 the end misses 1.75 by exactly the tolerance (0.5), which rpg does not accept.
  EXPECT_EQ(SelectSegmentPairs({0, 0.75, 1.25}, 1.0, 0.5), (Pairs{{0, 1}}));
}

TEST(SegmentErrors, PairSelectionEqualsTheLiteralScan) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> step(0.0, 0.3);
  std::bernoulli_distribution still(0.2);
  std::vector<double> d = {0.0};
  for (int k = 0; k < 400; ++k) d.push_back(d.back() + (still(rng) ? 0.0 : step(rng)));
  for (const double length : {0.5, 3.0, 17.0, 60.0}) {
    EXPECT_EQ(SelectSegmentPairs(d, length, 0.2), BruteForcePairs(d, length, 0.2)) << length;
  }
}

TEST(SegmentErrors, ScaleErrorIsAPercentOfTheLength) {
  const std::vector<SE3d> ref = EvenLine(9);
  std::vector<SE3d> est;
  for (const SE3d& pose : ref) est.emplace_back(pose.so3(), 1.1 * pose.translation());
  const SegmentErrors s = ComputeSegmentErrors(ref, est, Lengths({1.0})).front();
  ASSERT_EQ(s.pairs.size(), 5u);
  for (std::size_t k = 0; k < s.pairs.size(); ++k) {
    EXPECT_NEAR(s.translation_m[k], 0.1, 1e-12);
    EXPECT_NEAR(s.translation_percent[k], 10.0, 1e-9);
    EXPECT_NEAR(s.rotation_deg[k], 0.0, 1e-9);
  }
  EXPECT_NEAR(s.translation_percent_stats.median, 10.0, 1e-9);
}

TEST(SegmentErrors, HeadingDriftIsYawAndTiltDriftIsGravity) {
  const std::vector<SE3d> ref = EvenLine(9);
  std::vector<SE3d> yawing;
  std::vector<SE3d> tilting;
  for (std::size_t k = 0; k < ref.size(); ++k) {
    const double deg = static_cast<double>(k);  // 1 degree more at each pose
    yawing.emplace_back(AboutAxis(Eigen::Vector3d::UnitZ(), deg), ref[k].translation());
    tilting.emplace_back(AboutAxis(Eigen::Vector3d::UnitX(), deg), ref[k].translation());
  }
  const SegmentErrors yaw = ComputeSegmentErrors(ref, yawing, Lengths({1.0})).front();
  const SegmentErrors tilt = ComputeSegmentErrors(ref, tilting, Lengths({1.0})).front();
  ASSERT_EQ(yaw.pairs.size(), 5u);
  ASSERT_EQ(tilt.pairs.size(), 5u);
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_NEAR(yaw.rotation_deg[k], 4.0, 1e-9);
    EXPECT_NEAR(yaw.rotation_deg_per_m[k], 4.0, 1e-9);
    EXPECT_NEAR(yaw.yaw_deg[k], 4.0, 1e-9);
    EXPECT_NEAR(yaw.gravity_deg[k], 0.0, 1e-9);
    EXPECT_NEAR(tilt.rotation_deg[k], 4.0, 1e-9);
    EXPECT_NEAR(tilt.yaw_deg[k], 0.0, 1e-9);
    EXPECT_NEAR(tilt.gravity_deg[k], 4.0, 1e-9);
    // Start i's heading is i degrees off, so the 1 m step seen from it misses by 2 sin(i/2).
    const double i = static_cast<double>(yaw.pairs[k].first);
    EXPECT_NEAR(yaw.translation_m[k], 2.0 * std::sin(0.5 * i * kDegToRad), 1e-12);
  }
}

TEST(SegmentErrors, DefaultLengthsAreRpgsFractionsTruncatedToCentimetres) {
  const std::vector<double> lengths = DefaultSegmentLengths(123.456, {0.1, 0.2, 0.3, 0.4, 0.5});
  const std::vector<double> expected = {12.34, 24.69, 37.03, 49.38, 61.72};
  ASSERT_EQ(lengths.size(), expected.size());
  for (std::size_t k = 0; k < lengths.size(); ++k) EXPECT_NEAR(lengths[k], expected[k], 1e-9);

  const auto segments = ComputeSegmentErrors(EvenLine(41), EvenLine(41), SegmentErrorOptions{});
  ASSERT_EQ(segments.size(), 5u);  // 10 m path: 1, 2, 3, 4, 5 m
  EXPECT_DOUBLE_EQ(segments[4].length_m, 5.0);
  // Starts before 6 m (0..23) find an end within 1 m (20%) of 5 m further.
  EXPECT_EQ(segments[4].pairs.size(), 24u);
}

TEST(SegmentErrors, ALengthLongerThanThePathHasNoPairs) {
  const auto segments = ComputeSegmentErrors(EvenLine(9), EvenLine(9), Lengths({1.0, 5.0}));
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_FALSE(segments[0].empty());
  EXPECT_TRUE(segments[1].empty());
}

TEST(SegmentErrors, OptionsCheckThemselves) {
  EXPECT_THROW(Lengths({-1.0}).Check(), OptionError);
  SegmentErrorOptions bad_fraction;
  bad_fraction.fractions = {1.5};
  EXPECT_THROW(bad_fraction.Check(), OptionError);
  SegmentErrorOptions bad_tolerance;
  bad_tolerance.max_length_difference = 0.0;
  EXPECT_THROW(bad_tolerance.Check(), OptionError);
  EXPECT_NO_THROW(SegmentErrorOptions{}.Check());
}

}  // namespace
}  // namespace pkslam
