#include "keyframe/vins_parallax_selector.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pkslam {
namespace {

constexpr double kVinsF = 460.0;  // so a pixel here is a VINS-Mono pixel

// `points` tracked features; each sits at (100 + i, 200) px shifted by `shift_px` in u.
SelectorInput VinsInput(FrameId frame, int points, double shift_px,
                    const SO3d& camera_from_world_r = {}) {
  SelectorInput in;
  in.sensor = Sensor::kStereo;
  in.fps = 20;
  in.fx = in.fy = kVinsF;
  in.cx = 376;
  in.cy = 240;
  in.frame_id = frame;
  in.t_ns = frame * 50'000'000;
  in.last_keyframe_frame_id = 0;
  in.local_mapping_idle = true;
  in.keyframes_in_map = 5;
  in.camera_from_world = SE3d(camera_from_world_r, Eigen::Vector3d::Zero());
  for (int i = 0; i < points; ++i) {
    SelectorPoint p;
    p.id = i;
    p.uv = Eigen::Vector2d(100 + i + shift_px, 200);
    p.in_last_keyframe = true;
    in.points.push_back(p);
  }
  return in;
}

TEST(VinsParallaxSelector, ParallaxBetweenTheLastKeptAndTheSecondLatestFrame) {
  VinsParallaxSelector s({});
  s.OnKeyFrameInserted(VinsInput(0, 100, 0));
  // Frame 1 moved 11 px, but it is the latest frame: the rule looks at the second-latest
  // (the keyframe itself, no parallax yet).
  auto d = s.Decide(VinsInput(1, 100, 11));
  EXPECT_FALSE(d.insert);
  // Frame 2: the second-latest (frame 1) is 11 px from the keyframe: 11 >= 10 (at f = 460).
  d = s.Decide(VinsInput(2, 100, 12));
  EXPECT_TRUE(d.insert);
  EXPECT_EQ(d.reason, "parallax");
  EXPECT_NEAR(d.trace.at("parallax_px"), 11.0, 1e-9);

  VinsParallaxSelector t({});
  t.OnKeyFrameInserted(VinsInput(0, 100, 0));
  t.Decide(VinsInput(1, 100, 9));
  d = t.Decide(VinsInput(2, 100, 30));  // the latest frame's motion does not count yet
  EXPECT_FALSE(d.insert);
  EXPECT_NEAR(d.trace.at("parallax_px"), 9.0, 1e-9);
}

TEST(VinsParallaxSelector, ThresholdIsFocalNormalised) {
  // With a 920 px camera, 10 VINS pixels are 20 image pixels.
  VinsParallaxSelector s({});
  auto kf = VinsInput(0, 100, 0);
  kf.fx = kf.fy = 920;
  s.OnKeyFrameInserted(kf);
  auto f1 = VinsInput(1, 100, 19);
  f1.fx = f1.fy = 920;
  s.Decide(f1);
  auto f2 = VinsInput(2, 100, 19);
  f2.fx = f2.fy = 920;
  EXPECT_FALSE(s.Decide(f2).insert);  // 9.5 VINS pixels
}

TEST(VinsParallaxSelector, FewTrackedFeaturesOrNoneSharedMakeAKeyframe) {
  VinsParallaxSelector s({});
  s.OnKeyFrameInserted(VinsInput(0, 100, 0));
  EXPECT_EQ(s.Decide(VinsInput(1, 19, 0)).reason, "few-tracked");  // < 20 tracked
  VinsParallaxSelector t({});
  t.OnKeyFrameInserted(VinsInput(0, 100, 0));
  auto other = VinsInput(1, 100, 0);
  for (auto& p : other.points) p.id += 1000;  // nothing shared with the keyframe
  t.Decide(other);
  EXPECT_EQ(t.Decide(VinsInput(2, 100, 0)).reason, "few-tracked");
}

TEST(VinsParallaxSelector, RotationCompensationWithAnInitialisedImu) {
  // A pure rotation about the camera's y axis by 0.05 rad shifts every feature by ~23 px;
  // compensated, the parallax is ~0.
  const SO3d rotation = SO3d::Exp(Eigen::Vector3d(0, 0.05, 0));
  auto frame = [&](FrameId id, bool rotated, bool inertial) {
    SelectorInput in = VinsInput(id, 100, 0, rotated ? rotation : SO3d());
    if (rotated) {
      for (auto& p : in.points) {
        const Eigen::Vector3d bearing((p.uv.x() - in.cx) / kVinsF, (p.uv.y() - in.cy) / kVinsF, 1);
        const Eigen::Vector3d r = rotation * bearing;
        p.uv = Eigen::Vector2d(kVinsF * r.x() / r.z() + in.cx, kVinsF * r.y() / r.z() + in.cy);
      }
    }
    if (inertial) {
      in.sensor = Sensor::kStereoInertial;
      in.imu_initialized = true;
    }
    return in;
  };
  for (bool inertial : {false, true}) {
    VinsParallaxSelector s({});
    s.OnKeyFrameInserted(frame(0, false, inertial));
    s.Decide(frame(1, true, inertial));
    const auto d = s.Decide(frame(2, true, inertial));
    if (inertial) {
      EXPECT_NEAR(d.trace.at("parallax_px"), 0.0, 1e-6);
      EXPECT_FALSE(d.insert);
    } else {
      EXPECT_GT(d.trace.at("parallax_px"), 20.0);
      EXPECT_TRUE(d.insert);
    }
  }
}

}  // namespace
}  // namespace pkslam
