#include "evaluation/kitti_error.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/util/error.h"

namespace pkslam {
namespace {

// `count` poses 1 m apart along x; the estimate optionally stretched and turning about z.
std::vector<SE3d> Line(std::size_t count, double scale = 1.0, double yaw_per_frame = 0.0) {
  std::vector<SE3d> poses;
  for (std::size_t k = 0; k < count; ++k) {
    const double x = static_cast<double>(k);
    poses.emplace_back(SO3d::Exp(Eigen::Vector3d(0, 0, yaw_per_frame * x)),
                       Eigen::Vector3d(scale * x, 0, 0));
  }
  return poses;
}

TEST(KittiErrors, SegmentsEndAtTheFirstFramePastTheLength) {
  // 1 m per frame: a 100 m segment from frame 0 ends at frame 101 (the devkit's strict >).
  const auto e = ComputeKittiErrors(Line(300), Line(300));
  ASSERT_FALSE(e.empty());
  EXPECT_EQ(e.segments.front().first, 0u);
  EXPECT_EQ(e.segments.front().last, 101u);
  EXPECT_EQ(e.segments.front().length_m, 100.0);
  // Starts every 10 frames; 100 m segments need first + 101 <= 299, 200 m first + 201 <= 299.
  std::size_t n100 = 0, n200 = 0;
  for (const auto& s : e.segments) {
    EXPECT_EQ(s.first % 10, 0u);
    n100 += s.length_m == 100.0;
    n200 += s.length_m == 200.0;
    EXPECT_EQ(s.translation_per_m, 0.0);
  }
  EXPECT_EQ(n100, 20u);  // first 0, 10, ..., 190
  EXPECT_EQ(n200, 10u);  // first 0, 10, ..., 90
  EXPECT_EQ(e.segments.size(), 30u);
  ASSERT_EQ(e.per_length.size(), 2u);
  EXPECT_EQ(e.per_length[1].segments, 10u);
}

TEST(KittiErrors, AScaleErrorIsItsPercentOfEachSegment) {
  const auto e = ComputeKittiErrors(Line(350), Line(350, 1.01));
  ASSERT_FALSE(e.empty());
  double mean = 0;
  for (const auto& s : e.segments) {
    // The segment spans L + 1 m of truth, of which 1% is missing.
    const double expected = 0.01 * (s.length_m + 1.0) / s.length_m;
    EXPECT_NEAR(s.translation_per_m, expected, 1e-12);
    EXPECT_NEAR(s.rotation_rad_per_m, 0.0, 1e-12);
    mean += expected;
  }
  mean /= static_cast<double>(e.segments.size());
  EXPECT_NEAR(e.translation_percent, 100.0 * mean, 1e-10);
  EXPECT_NEAR(e.per_length[0].translation_percent, 100.0 * 0.01 * 101.0 / 100.0, 1e-10);
}

TEST(KittiErrors, AHeadingDriftIsItsAnglePerMetre) {
  const double yaw = 1e-4;  // rad per frame (and per metre)
  const auto e = ComputeKittiErrors(Line(250), Line(250, 1.0, yaw));
  ASSERT_FALSE(e.empty());
  for (const auto& s : e.segments) {
    EXPECT_NEAR(s.rotation_rad_per_m, yaw * (s.length_m + 1.0) / s.length_m, 1e-12);
  }
  const double deg = 180.0 / M_PI;
  EXPECT_NEAR(e.per_length[0].rotation_deg_per_100m, 100.0 * deg * yaw * 101.0 / 100.0, 1e-9);
}

TEST(KittiErrors, ShortSequencesHaveNoSegmentAndOptionsCheckThemselves) {
  EXPECT_TRUE(ComputeKittiErrors(Line(90), Line(90)).empty());
  KittiErrorOptions bad;
  bad.step_frames = 0;
  EXPECT_THROW(bad.Check(), OptionError);
  bad = KittiErrorOptions{};
  bad.lengths_m = {-5};
  EXPECT_THROW(bad.Check(), OptionError);
}

}  // namespace
}  // namespace pkslam
