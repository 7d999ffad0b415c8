#include "system/estimate_health.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace pkslam {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

std::vector<FrameRecord> Records(const std::vector<TrackingState>& states) {
  std::vector<FrameRecord> out(states.size());
  for (std::size_t i = 0; i < states.size(); ++i) {
    out[i].t_ns = static_cast<std::int64_t>(i) * 1'000'000'000;  // one frame per second
    out[i].state = states[i];
  }
  return out;
}

LoopEvent Merge(double t_s, double correction_m) {
  LoopEvent e;
  e.t_ns = static_cast<std::int64_t>(t_s * 1e9);
  e.correction_m = correction_m;
  return e;
}

TEST(LostForGoodTimes, CountsOnlyTheStepsFromTrackingToANewStart) {
  using S = TrackingState;
  // Initialising, a relocalised loss (RECENTLY_LOST -> OK: not for good), then a loss for
  // good at 6 s (new map: NOT_INITIALIZED) and one at 9 s (LOST).
  const auto records = Records({S::kNotInitialized, S::kNotInitialized, S::kOk, S::kRecentlyLost,
                                S::kOk, S::kRecentlyLost, S::kNotInitialized, S::kOk, S::kOk,
                                S::kLost});
  EXPECT_THAT(LostForGoodTimes(records), ElementsAre(6.0, 9.0));
  EXPECT_TRUE(LostForGoodTimes(Records({S::kNotInitialized, S::kOk, S::kOk})).empty());
}

TEST(AssessEstimate, ACleanRunIsNotSuspect) {
  const EstimateHealth h = AssessEstimate({}, {}, 1);
  EXPECT_FALSE(h.suspect());
  EXPECT_EQ(h.largest_merge_correction_m, 0.0);
}

TEST(AssessEstimate, NamesEachLossAndTheMergeThatJoinedItsMapBack) {
  // Lost at 14 s, merged back at 80 s with a 3.22 m correction; lost again at 90 s, never
  // merged, so two maps remain.
  const EstimateHealth h = AssessEstimate({14.0, 90.0}, {Merge(80.0, 3.22)}, 2);
  ASSERT_TRUE(h.suspect());
  ASSERT_EQ(h.warnings.size(), 3u);
  EXPECT_THAT(h.warnings[0], HasSubstr("t = 14.000 s"));
  EXPECT_THAT(h.warnings[0], HasSubstr("merged back at t = 80.000 s, moving a keyframe 3.22 m"));
  EXPECT_THAT(h.warnings[1], HasSubstr("continues in a new (or reset) map"));
  EXPECT_THAT(h.warnings[2], HasSubstr("2 maps at the end"));
  EXPECT_DOUBLE_EQ(h.largest_merge_correction_m, 3.22);
}

TEST(AssessEstimate, CapsTheListOfLosses) {
  std::vector<double> losses;
  for (int i = 0; i < 8; ++i) losses.push_back(10.0 * i);
  const EstimateHealth h = AssessEstimate(losses, {}, 1);
  ASSERT_EQ(h.warnings.size(), kMaxLossWarnings + 1);
  EXPECT_THAT(h.warnings.back(), HasSubstr("3 more times"));
}

TEST(AssessEstimate, AMergeWithoutALossAloneIsNotSuspect) {
  // --load-map: the run's map is merged into the loaded one; nothing was lost.
  const EstimateHealth h = AssessEstimate({}, {Merge(5.0, 12.0)}, 1);
  EXPECT_FALSE(h.suspect());
  EXPECT_DOUBLE_EQ(h.largest_merge_correction_m, 12.0);
}

TEST(LocalisationGaps, OneGapPerStretchWithoutAPose) {
  std::vector<FrameRecord> records(8);
  const TrackingState states[] = {TrackingState::kLost, TrackingState::kLost, TrackingState::kOk,
                                  TrackingState::kOk,   TrackingState::kLost, TrackingState::kOk,
                                  TrackingState::kLost, TrackingState::kLost};
  for (int i = 0; i < 8; ++i) {
    records[i].t_ns = std::int64_t{1'000'000'000} * (i + 1);
    records[i].state = states[i];
  }
  const auto gaps = LocalisationGaps(records);
  ASSERT_EQ(gaps.size(), 3u);
  EXPECT_EQ(gaps[0].begin_s, 1.0);
  EXPECT_EQ(gaps[0].relocalised_s, 3.0);
  EXPECT_EQ(gaps[0].frames, 2);
  EXPECT_EQ(gaps[1].begin_s, 5.0);
  EXPECT_EQ(gaps[1].relocalised_s, 6.0);
  EXPECT_EQ(gaps[2].frames, 2);
  EXPECT_FALSE(gaps[2].relocalised_s);
}

TEST(NoEstimateReason, TooFewPosesAreNoEstimate) {
  EXPECT_EQ(NoEstimateReason(40, 40, false, true), "");
  EXPECT_EQ(NoEstimateReason(1, 1, false, false), "");  // a one-frame run (map load timing)
  EXPECT_EQ(NoEstimateReason(200, 20, false, false), "");
  const std::string never = NoEstimateReason(40, 0, true, true);
  EXPECT_NE(never.find("only 0 of 40 frames have a pose (at least 4 needed)"), std::string::npos)
      << never;
  EXPECT_NE(never.find("monocular map needs two views"), std::string::npos) << never;
  EXPECT_NE(NoEstimateReason(200, 19, false, false).find("lost for most"), std::string::npos);
  EXPECT_NE(NoEstimateReason(10, 2, true, false).find("50 keypoints"), std::string::npos);
  EXPECT_NE(NoEstimateReason(0, 0, true, false), "");
}

TEST(NoEstimateReason, MakesTheEstimateSuspect) {
  EstimateHealth h;
  EXPECT_FALSE(h.suspect());
  h.no_estimate = NoEstimateReason(40, 0, true, true);
  EXPECT_TRUE(h.suspect());
}

}  // namespace
}  // namespace pkslam
