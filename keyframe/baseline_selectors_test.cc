#include "keyframe/baseline_selectors.h"

#include <gtest/gtest.h>

namespace pkslam {
namespace {

SelectorInput Input(FrameId frame, int points, double moved_m = 0) {
  SelectorInput in;
  in.sensor = Sensor::kStereo;
  in.fps = 20;
  in.frame_id = frame;
  in.t_ns = frame * 50'000'000;
  in.last_keyframe_frame_id = 0;
  in.local_mapping_idle = true;
  in.keyframes_in_map = 5;
  in.camera_from_world = SE3d(SO3d(), Eigen::Vector3d(-moved_m, 0, 0));
  for (int i = 0; i < points; ++i) {
    SelectorPoint p;
    p.id = i;
    p.position_world = Eigen::Vector3d(0.01 * i, 0, 4.0);  // 4 m in front
    p.uv = Eigen::Vector2d(100 + i % 500, 200);
    p.in_last_keyframe = true;
    in.points.push_back(p);
  }
  return in;
}

TEST(IntervalSelector, EveryNFrames) {
  BaselineOptions o;
  o.interval_frames = 5;
  BaselineSelector s(BaselineKind::kInterval, o);
  EXPECT_FALSE(s.Decide(Input(4, 0)).insert);
  EXPECT_TRUE(s.Decide(Input(5, 0)).insert);
}

TEST(IntervalSelector, EveryTSeconds) {
  BaselineOptions o;
  o.interval_frames = 0;
  o.interval_seconds = 0.5;
  BaselineSelector s(BaselineKind::kInterval, o);
  EXPECT_FALSE(s.Decide(Input(9, 0)).insert);  // 0.45 s
  EXPECT_TRUE(s.Decide(Input(10, 0)).insert);  // 0.5 s
}

TEST(PtamSelector, NeedsBothFramesAndDistance) {
  BaselineSelector s(BaselineKind::kPtam, {});
  EXPECT_FALSE(s.Decide(Input(19, 100, 1.0)).insert);  // too few frames
  EXPECT_FALSE(s.Decide(Input(25, 100, 0.3)).insert);  // 0.3 m < 0.1 * 4 m
  const auto d = s.Decide(Input(25, 100, 0.5));
  EXPECT_TRUE(d.insert);
  EXPECT_NEAR(d.trace.at("distance_ratio"), 0.125, 1e-12);
}

TEST(MatchCountSelector, FewerThanFourHundredMatches) {
  BaselineSelector s(BaselineKind::kMatchCount, {});
  EXPECT_FALSE(s.Decide(Input(3, 400)).insert);
  EXPECT_TRUE(s.Decide(Input(3, 399)).insert);
}

TEST(BaselineSelectors, InertialBeforeImuInitUsesTheQuarterSecondRule) {
  BaselineSelector s(BaselineKind::kMatchCount, {});
  SelectorInput in = Input(4, 10);
  in.sensor = Sensor::kStereoInertial;
  EXPECT_FALSE(s.Decide(in).insert);  // 0.2 s, IMU not initialised
  in.t_ns = 250'000'000;
  EXPECT_TRUE(s.Decide(in).insert);
}

}  // namespace
}  // namespace pkslam
