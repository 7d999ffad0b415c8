// Local mapping's motion clocks of an inertial map (mapping/inertial_motion_clock.h), on a
// chain of keyframes that moves, stands still and creeps.
#include "mapping/inertial_motion_clock.h"

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <vector>

#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

constexpr std::int64_t kPeriodNs = 50'000'000;  // the synthetic map's keyframes, 20 Hz

class InertialMotionClockTest : public ::testing::Test {
 protected:
  // Keyframes 50 ms apart whose camera centres advance along x by `steps` (metres).
  void MakeChain(const std::vector<double>& steps) {
    std::vector<SE3d> camera_from_world;
    double x = 0;
    camera_from_world.push_back(SE3d());
    for (double step : steps) {
      x += step;
      camera_from_world.push_back(SE3d(SO3d(), Eigen::Vector3d(-x, 0, 0)));
    }
    map_ = testing::MakeMap(&atlas_, testing::MakeScene(300, 2),
                            testing::MakeStereoRig(Sensor::kStereoInertial), camera_from_world, {});
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    for (std::size_t k = 1; k < map_.keyframes.size(); ++k) {
      ASSERT_EQ(map_.keyframes[k]->t_ns() - map_.keyframes[k - 1]->t_ns(), kPeriodNs);
      atlas_.current_map()->inertial_chain().Append(lock, map_.keyframes[k - 1].get(),
                                                    map_.keyframes[k].get(), std::nullopt);
    }
  }
  const KeyFrame& kf(int k) const { return *map_.keyframes[k]; }

  Atlas atlas_;
  testing::SyntheticMap map_;
  InertialMappingOptions options_;  // moving: 2 cm or 0.035 rad, intervals up to 1 s
  InertialMotionClock clock_;
};

TEST_F(InertialMotionClockTest, OnlyIntervalsWithMotionCount) {
  MakeChain({0.1, 0.1, 0.0, 0.01, 0.1});
  auto lock = MapReader(atlas_).Lock();
  EXPECT_EQ(clock_.Observe(kf(0), false, options_).step_s, 0) << "no predecessor";
  const double expected[] = {0.05, 0.05, 0.0, 0.0, 0.05};
  for (int k = 1; k <= 5; ++k) {
    const KeyFrameMotion motion = clock_.Observe(kf(k), false, options_);
    EXPECT_DOUBLE_EQ(motion.step_s, expected[k - 1]) << "keyframe " << k;
    EXPECT_FALSE(motion.slow_motion) << "mTinit runs only between initialisation and VIBA2";
    clock_.Advance(motion.step_s);
  }
  EXPECT_NEAR(clock_.moving_s(), 0.15, 1e-12);
  options_.moving_max_interval_s = 0.02;
  EXPECT_DOUBLE_EQ(clock_.Observe(kf(5), false, options_).step_s, 0.02) << "capped";
}

TEST_F(InertialMotionClockTest, SlowMotionIsFlaggedUntilTenSecondsOfTwoStepMotion) {
  // Two steps of 3 cm: more than 5 cm in two steps (mTinit grows), less than 10 cm (slow).
  constexpr int kSteps = 230;
  MakeChain(std::vector<double>(kSteps, 0.03));
  auto lock = MapReader(atlas_).Lock();
  clock_.Observe(kf(0), true, options_);
  clock_.Observe(kf(1), true, options_);  // one step only: no two-step motion yet
  EXPECT_EQ(clock_.two_step_motion_s(), 0);
  int flagged = 0;
  for (int k = 2; k <= kSteps; ++k) {
    const KeyFrameMotion motion = clock_.Observe(kf(k), true, options_);
    flagged += motion.slow_motion ? 1 : 0;
    EXPECT_EQ(motion.slow_motion, clock_.two_step_motion_s() < 10.0) << "keyframe " << k;
  }
  EXPECT_NEAR(clock_.two_step_motion_s(), (kSteps - 1) * 0.05, 1e-9);
  EXPECT_NEAR(flagged, 199, 1) << "50 ms per keyframe: under 10 s for the first 200 intervals";
  EXPECT_GT(flagged, 0);
  clock_.Restart();
  EXPECT_EQ(clock_.two_step_motion_s(), 0);
  EXPECT_TRUE(clock_.Observe(kf(kSteps), true, options_).slow_motion);
}

TEST_F(InertialMotionClockTest, AKeyframeOfAnotherMapRestartsTheClocks) {
  MakeChain({0.1, 0.1, 0.1});
  {
    auto lock = MapReader(atlas_).Lock();
    for (int k = 0; k <= 3; ++k) clock_.Advance(clock_.Observe(kf(k), true, options_).step_s);
  }
  EXPECT_NEAR(clock_.moving_s(), 0.15, 1e-12);
  EXPECT_GT(clock_.two_step_motion_s(), 0);
  const testing::SyntheticMap first = map_;  // keeps the first map's keyframes alive
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    atlas_.CreateNewMap(lock);
  }
  MakeChain({0.1});
  auto lock = MapReader(atlas_).Lock();
  EXPECT_EQ(clock_.Observe(kf(0), true, options_).step_s, 0);
  EXPECT_EQ(clock_.moving_s(), 0);
  EXPECT_EQ(clock_.two_step_motion_s(), 0);
}

}  // namespace
}  // namespace pkslam
