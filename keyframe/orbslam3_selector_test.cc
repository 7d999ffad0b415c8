#include "keyframe/orbslam3_selector.h"

#include <gtest/gtest.h>

#include "core/util/error.h"

namespace pkslam {
namespace {

// A stereo frame 5 frames after the last keyframe, tracking well, mapping idle.
SelectorInput StereoInput() {
  SelectorInput in;
  in.sensor = Sensor::kStereo;
  in.fps = 20;
  in.frame_id = 105;
  in.last_keyframe_frame_id = 100;
  in.t_ns = 5'250'000'000;
  in.last_keyframe_t_ns = 5'000'000'000;
  in.keyframes_in_map = 10;
  in.reference_tracked_points = 400;
  in.inliers = 380;
  in.tracked_close = 200;
  in.untracked_close = 20;
  in.local_mapping_idle = true;
  return in;
}

TEST(OrbSlam3Selector, NoKeyframeWhileTrackingWell) {
  OrbSlam3Selector s;
  EXPECT_FALSE(s.Decide(StereoInput()).insert);
}

TEST(OrbSlam3Selector, FewerInliersThanRatioWithIdleMappingInserts) {
  OrbSlam3Selector s;
  SelectorInput in = StereoInput();
  in.inliers = 290;  // < 0.75 * 400
  const auto d = s.Decide(in);
  EXPECT_TRUE(d.insert);
  EXPECT_NE(d.reason.find("c1b"), std::string::npos);
  EXPECT_NE(d.reason.find("c2"), std::string::npos);
}

TEST(OrbSlam3Selector, BusyMappingNeedsMaxFramesOrWeakTracking) {
  OrbSlam3Selector s;
  SelectorInput in = StereoInput();
  in.inliers = 290;
  in.local_mapping_idle = false;
  // c1a false (5 < 20 frames), c1b false (busy), c1c false (290 > 100): no keyframe.
  EXPECT_FALSE(s.Decide(in).insert);
  in.frame_id = 120;  // c1a
  const auto d = s.Decide(in);
  EXPECT_TRUE(d.insert);  // stereo, queue 0 < 3
  EXPECT_TRUE(d.interrupt_local_ba);
  in.local_mapping_queue = 3;
  EXPECT_FALSE(s.Decide(in).insert);
}

TEST(OrbSlam3Selector, CloseRuleTriggersForStereo) {
  OrbSlam3Selector s;
  SelectorInput in = StereoInput();
  in.tracked_close = 99;
  in.untracked_close = 71;
  EXPECT_TRUE(s.Decide(in).insert);
  in.untracked_close = 70;  // strict inequality
  EXPECT_FALSE(s.Decide(in).insert);
}

TEST(OrbSlam3Selector, MonocularUsesRatioPointNineAndNoClosePoints) {
  OrbSlam3Selector s;
  SelectorInput in = StereoInput();
  in.sensor = Sensor::kMonocular;
  in.inliers = 350;  // < 0.9 * 400 but > 0.75 * 400
  EXPECT_TRUE(s.Decide(in).insert);
  in.local_mapping_idle = false;
  in.frame_id = 130;  // c1a holds but monocular never inserts while mapping is busy
  const auto d = s.Decide(in);
  EXPECT_FALSE(d.insert);
  EXPECT_TRUE(d.interrupt_local_ba);
}

TEST(OrbSlam3Selector, InertialBeforeImuInitEveryQuarterSecond) {
  OrbSlam3Selector s;
  SelectorInput in = StereoInput();
  in.sensor = Sensor::kStereoInertial;
  in.imu_initialized = false;
  in.t_ns = in.last_keyframe_t_ns + 240'000'000;
  EXPECT_FALSE(s.Decide(in).insert);
  in.t_ns = in.last_keyframe_t_ns + 250'000'000;
  EXPECT_TRUE(s.Decide(in).insert);
}

TEST(OrbSlam3Selector, InertialTimeConditionC3) {
  OrbSlam3Selector s;
  SelectorInput in = StereoInput();
  in.sensor = Sensor::kStereoInertial;
  in.imu_initialized = true;
  in.t_ns = in.last_keyframe_t_ns + 490'000'000;
  EXPECT_FALSE(s.Decide(in).insert);
  in.t_ns = in.last_keyframe_t_ns + 500'000'000;
  const auto d = s.Decide(in);
  EXPECT_TRUE(d.insert);
  EXPECT_NE(d.reason.find("c3"), std::string::npos);
}

TEST(OrbSlam3Selector, MonoInertialWeakTrackingC4) {
  OrbSlam3Selector s;
  SelectorInput in = StereoInput();
  in.sensor = Sensor::kMonocularInertial;
  in.imu_initialized = true;
  in.inliers = 60;
  in.reference_tracked_points = 60;  // c2 false
  in.local_mapping_idle = true;
  EXPECT_TRUE(s.Decide(in).insert);
  in.inliers = 15;  // not > 15
  EXPECT_FALSE(s.Decide(in).insert);
  in.recently_lost = true;
  EXPECT_TRUE(s.Decide(in).insert);
}

TEST(OrbSlam3Selector, SafetyExits) {
  OrbSlam3Selector s;
  SelectorInput in = StereoInput();
  in.inliers = 100;
  in.only_tracking = true;
  EXPECT_FALSE(s.Decide(in).insert);
  in.only_tracking = false;
  in.local_mapping_stopped = true;
  EXPECT_FALSE(s.Decide(in).insert);
  in.local_mapping_stopped = false;
  in.last_relocalisation_frame_id = 100;  // within fps frames after relocalisation
  in.keyframes_in_map = 30;
  EXPECT_EQ(s.Decide(in).reason, "after-reloc");
}

// While local mapping initialises the IMU, v1.0 inserts (as when idle) and v0.3 declines.
TEST(OrbSlam3Selector, ImuInitialisationExitOnlyInTheV03Reading) {
  SelectorInput in = StereoInput();
  in.sensor = Sensor::kStereoInertial;
  in.imu_initialized = true;
  in.local_mapping_idle = false;
  in.local_mapping_initializing = true;
  in.t_ns = in.last_keyframe_t_ns + 500'000'000;  // c3 holds
  OrbSlam3Selector v10;
  EXPECT_TRUE(v10.Decide(in).insert);
  OrbSlam3SelectorOptions o;
  o.no_keyframe_while_imu_initialises = true;
  OrbSlam3Selector v03(o);
  const auto d = v03.Decide(in);
  EXPECT_FALSE(d.insert);
  EXPECT_EQ(d.reason, "imu-initialising");
  in.local_mapping_initializing = false;
  in.local_mapping_idle = true;
  EXPECT_TRUE(v03.Decide(in).insert);
}

TEST(OrbSlam3SelectorOptions, CheckRejectsBadValues) {
  OrbSlam3SelectorOptions o;
  o.inertial_interval_s = 0;
  EXPECT_THROW(o.Check(), OptionError);
}

}  // namespace
}  // namespace pkslam
