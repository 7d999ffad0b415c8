#include "keyframe/pks_selector.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/util/error.h"
#include "keyframe/selector_factory.h"

namespace pkslam {
namespace {

constexpr double kFx = 435.0;
constexpr int kWidth = 752;
constexpr int kHeight = 480;

// A camera at `center` looking at `target` (y down, z forward).
SE3d LookAt(const Eigen::Vector3d& center, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - center).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d(0, 1, 0).cross(z).normalized() * -1.0;
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d world_from_camera_r;
  world_from_camera_r << x, y, z;
  return SE3d(world_from_camera_r, center).Inverse();
}

struct Patch {
  Eigen::Vector3d center;
  Eigen::Vector3d normal;
};

// 3x3 points (5 cm apart) on a small plane per patch; ids are stable across frames.
std::vector<std::pair<MapPointId, Eigen::Vector3d>> PatchPoints(const std::vector<Patch>& patches) {
  std::vector<std::pair<MapPointId, Eigen::Vector3d>> out;
  MapPointId id = 0;
  for (const Patch& p : patches) {
    const Eigen::Vector3d t1 = p.normal.unitOrthogonal();
    const Eigen::Vector3d t2 = p.normal.cross(t1);
    for (int a = -1; a <= 1; ++a) {
      for (int b = -1; b <= 1; ++b) {
        // A slight irregular offset so neighbour distances are not tied.
        out.emplace_back(id++, p.center + 0.05 * a * t1 + (0.05 * b + 0.003 * a) * t2);
      }
    }
  }
  return out;
}

SelectorInput MakeInput(const std::vector<std::pair<MapPointId, Eigen::Vector3d>>& points,
                        const SE3d& camera_from_world, FrameId frame) {
  SelectorInput in;
  // The scenario keyframe: at -2.5 x, aimed at (0, 0, 2) (PksScenario::c0_, target_).
  in.last_keyframe_camera_from_world = LookAt({-2.5, 0, 0}, {0, 0, 2});
  in.sensor = Sensor::kStereo;
  in.fps = 20;
  in.image_width = kWidth;
  in.image_height = kHeight;
  in.frame_id = frame;
  in.t_ns = frame * 50'000'000;
  in.last_keyframe_frame_id = 0;
  in.last_keyframe_t_ns = 0;
  in.keyframes_in_map = 10;
  in.inliers = static_cast<int>(points.size());
  in.local_mapping_idle = true;
  in.camera_from_world = camera_from_world;
  for (const auto& [id, p] : points) {
    const Eigen::Vector3d c = camera_from_world * p;
    SelectorPoint sp;
    sp.id = id;
    sp.position_world = p;
    sp.uv =
        Eigen::Vector2d(kFx * c.x() / c.z() + kWidth / 2.0, kFx * c.y() / c.z() + kHeight / 2.0);
    sp.in_last_keyframe = true;
    in.points.push_back(sp);
  }
  return in;
}

class PksScenario : public ::testing::Test {
 protected:
  // Current camera at the origin looking along +z with patches 2 m away in the four corners
  // of its image; the keyframe camera was 2.5 m to the side, aimed at the same spot.
  const Eigen::Vector3d c0_{-2.5, 0, 0};
  const Eigen::Vector3d c1_{0, 0, 0};
  const Eigen::Vector3d target_{0, 0, 2};
  const std::vector<Eigen::Vector3d> centers_ = {
      {-0.8, -0.5, 2}, {0.8, -0.5, 2}, {-0.8, 0.5, 2}, {0.8, 0.5, 2}};  // TL, TR, BL, BR

  // A normal facing the keyframe camera: its viewing angle goes from 0 to the parallax.
  Patch Facing(const Eigen::Vector3d& p) const { return {p, (c0_ - p).normalized()}; }
  // A normal perpendicular to both rays: 90 degrees from either camera, no region change.
  Patch Grazing(const Eigen::Vector3d& p) const {
    return {p, (c0_ - p).cross(c1_ - p).normalized()};
  }
};

TEST_F(PksScenario, BalancedViewChangeTriggersTheCameraCriterion) {
  // TL and BR change region and viewing angle by > 30 deg (60.8 and 36.9 deg of parallax);
  // TR and BL do not.
  const auto points = PatchPoints(
      {Facing(centers_[0]), Grazing(centers_[1]), Grazing(centers_[2]), Facing(centers_[3])});
  PksOptions o;
  o.weak_tracking_ratio = 0;
  PksSelector s(o);
  s.OnKeyFrameInserted(MakeInput(points, LookAt(c0_, target_), 0));
  // Frame 1 (the reference): barely moved.
  const auto r = s.Decide(MakeInput(points, LookAt(c0_ + Eigen::Vector3d(0.03, 0, 0), target_), 1));
  EXPECT_EQ(r.reason, "no");
  ASSERT_EQ(r.trace.count("M_c"), 1u) << r.reason << " " << r.trace.size();
  EXPECT_EQ(r.trace.at("M_c"), 36);
  const auto d = s.Decide(MakeInput(points, LookAt(c1_, target_), 2));
  EXPECT_EQ(d.trace.at("D_c"), 18);
  EXPECT_GT(d.trace.at("D_c"), d.trace.at("Th_adaptive"));
  EXPECT_GT(d.trace.at("ECOG"), d.trace.at("COG"));
  EXPECT_TRUE(d.insert);
  EXPECT_NE(d.reason.find("camera"), std::string::npos) << d.reason;
}

TEST_F(PksScenario, AWorldChangeAfterTheKeyframeChangesNothing) {
  // IMU initialisation rotates (and shifts) the whole map after the keyframe was taken: the
  // keyframe, its points and the frame move together, so D, E and the decision must not change
  // (before, the snapshot's world-frame normals stayed in the old world: spurious view changes).
  const auto points = PatchPoints(
      {Facing(centers_[0]), Grazing(centers_[1]), Grazing(centers_[2]), Facing(centers_[3])});
  const SE3d new_from_old(SO3d::Exp(Eigen::Vector3d(0.3, -1.1, 0.7)), Eigen::Vector3d(1, -2, 3));
  auto moved = [&](SelectorInput in) {
    in.camera_from_world = in.camera_from_world * new_from_old.Inverse();
    in.last_keyframe_camera_from_world =
        in.last_keyframe_camera_from_world * new_from_old.Inverse();
    for (auto& p : in.points) p.position_world = new_from_old * p.position_world;
    return in;
  };
  PksOptions o;
  o.weak_tracking_ratio = 0;
  PksSelector plain(o);
  PksSelector changed(o);
  for (auto* s : {&plain, &changed})
    s->OnKeyFrameInserted(MakeInput(points, LookAt(c0_, target_), 0));
  const auto reference = MakeInput(points, LookAt(c0_ + Eigen::Vector3d(0.03, 0, 0), target_), 1);
  plain.Decide(reference);
  changed.Decide(moved(reference));
  const auto frame = MakeInput(points, LookAt(c1_, target_), 2);
  const auto a = plain.Decide(frame);
  const auto b = changed.Decide(moved(frame));
  EXPECT_EQ(a.trace.at("D_c"), b.trace.at("D_c"));
  EXPECT_EQ(a.trace.at("E_c"), b.trace.at("E_c"));
  EXPECT_EQ(a.insert, b.insert);
  EXPECT_TRUE(b.insert);
}

TEST_F(PksScenario, OneSidedViewChangeFailsTheBalanceCriterion) {
  // Only the TL patch changes: all effective points in one cell, ECOG = 0.
  const auto points = PatchPoints(
      {Facing(centers_[0]), Grazing(centers_[1]), Grazing(centers_[2]), Grazing(centers_[3])});
  PksOptions o;
  o.weak_tracking_ratio = 0;
  PksSelector s(o);
  s.OnKeyFrameInserted(MakeInput(points, LookAt(c0_, target_), 0));
  s.Decide(MakeInput(points, LookAt(c0_ + Eigen::Vector3d(0.03, 0, 0), target_), 1));
  const auto d = s.Decide(MakeInput(points, LookAt(c1_, target_), 2));
  EXPECT_EQ(d.trace.at("D_c"), 9);
  EXPECT_GT(d.trace.at("D_c"), d.trace.at("Th_adaptive"));  // criterion 1 holds...
  EXPECT_DOUBLE_EQ(d.trace.at("ECOG"), 0.0);                // ...criterion 2 does not
  EXPECT_FALSE(d.insert);
}

TEST_F(PksScenario, FewerThanSixPointsGiveNoCameraDecision) {
  auto points = PatchPoints({Facing(centers_[0])});
  points.resize(5);
  PksSelector s(PksOptions{});
  s.OnKeyFrameInserted(MakeInput(points, LookAt(c0_, target_), 0));
  const auto d = s.Decide(MakeInput(points, LookAt(c1_, target_), 2));
  EXPECT_EQ(d.trace.count("D_c"), 0u);
  EXPECT_EQ(d.reason.find("camera"), std::string::npos);
}

TEST_F(PksScenario, NoKeyframeSnapshotNoCameraDecisionAndResetForgets) {
  const auto points = PatchPoints(
      {Facing(centers_[0]), Grazing(centers_[1]), Grazing(centers_[2]), Facing(centers_[3])});
  PksOptions o;
  o.weak_tracking_ratio = 0;
  PksSelector s(o);
  EXPECT_FALSE(s.Decide(MakeInput(points, LookAt(c1_, target_), 2)).insert);
  s.OnKeyFrameInserted(MakeInput(points, LookAt(c0_, target_), 0));
  s.Reset();
  EXPECT_FALSE(s.Decide(MakeInput(points, LookAt(c1_, target_), 2)).insert);
}

TEST_F(PksScenario, CameraThatDidNotMoveTakesNoKeyframe) {
  const auto points = PatchPoints({Facing(centers_[0]), Facing(centers_[3])});
  PksSelector s(PksOptions{});
  s.OnKeyFrameInserted(MakeInput(points, LookAt(c0_, target_), 0));
  auto in = MakeInput(points, LookAt(c0_ + Eigen::Vector3d(0.01, 0, 0), target_), 30);
  in.tracked_close = 0;
  in.untracked_close = 500;  // would trigger the close-point rule otherwise
  EXPECT_EQ(s.Decide(in).reason, "still");
}

TEST(PksCombination, CloseRuleNeedsLocalMappingIdle) {
  const std::vector<std::pair<MapPointId, Eigen::Vector3d>> none;
  PksSelector s(PksOptions{});
  SelectorInput in = MakeInput(none, SE3d(), 3);
  in.inliers = 200;
  in.tracked_close = 10;
  in.untracked_close = 200;
  EXPECT_EQ(s.Decide(in).reason, "close");
  in.local_mapping_idle = false;  // busy: the released code's c3 waits (ORB-SLAM3 gates it too)
  EXPECT_EQ(s.Decide(in).reason, "no");
}

TEST(PksImu, AccelerationTriggerAgainstTheKeyframeInterval) {
  const std::vector<std::pair<MapPointId, Eigen::Vector3d>> none;
  auto input = [&](FrameId f, const Eigen::Vector3d& body, const Eigen::Vector3d& world) {
    SelectorInput in = MakeInput(none, SE3d(), f);
    in.sensor = Sensor::kStereoInertial;
    in.imu_initialized = true;
    in.t_ns = in.last_keyframe_t_ns + 100'000'000;  // below the 0.5 s time rule
    in.last_keyframe_camera_from_world = SE3d(SO3d(), Eigen::Vector3d(1, 0, 0));
    SelectorImuInterval imu;
    imu.dt = 0.05;
    imu.mean_accel = body;
    imu.mean_accel_world_no_gravity = world;
    in.imu_since_last_frame = imu;
    return in;
  };
  const Eigen::Vector3d g(0, 0, 9.81);
  PksSelector paper(PksOptions{});
  paper.OnKeyFrameInserted(input(0, g, Eigen::Vector3d::Zero()));
  EXPECT_FALSE(paper.Decide(input(1, g, {0.5, 0, 0})).insert);  // |da| 0.5
  const auto fire = paper.Decide(input(2, g, {1.2, 0, 0}));     // |da| 1.2 > 1
  EXPECT_TRUE(fire.insert);
  EXPECT_NEAR(fire.trace.at("delta_a"), 1.2, 1e-12);
}

TEST(PksImu, AccelerationOfTheKeyframeIntervalFollowsAWorldRotation) {
  const std::vector<std::pair<MapPointId, Eigen::Vector3d>> none;
  const SO3d new_from_old = SO3d::Exp(Eigen::Vector3d(0, 0, 1.2));
  auto input = [&](FrameId f, const SO3d& world_change, const Eigen::Vector3d& accel_world) {
    SelectorInput in = MakeInput(none, SE3d(), f);
    in.sensor = Sensor::kStereoInertial;
    in.imu_initialized = true;
    in.t_ns = in.last_keyframe_t_ns + 100'000'000;
    in.camera_from_world = SE3d(world_change.Inverse(), Eigen::Vector3d(-1, 0, 0));
    in.last_keyframe_camera_from_world = SE3d(world_change.Inverse(), Eigen::Vector3d(1, 0, 0));
    SelectorImuInterval imu;
    imu.dt = 0.05;
    imu.mean_accel_world_no_gravity = accel_world;
    in.imu_since_last_frame = imu;
    return in;
  };
  PksSelector s(PksOptions{});
  s.OnKeyFrameInserted(input(0, SO3d(), {2, 0, 0}));
  // The same specific force, expressed in the rotated world: no change.
  const auto d = s.Decide(input(1, new_from_old, new_from_old * Eigen::Vector3d(2, 0, 0)));
  EXPECT_NEAR(d.trace.at("delta_a"), 0.0, 1e-12);
  EXPECT_FALSE(d.insert);
}

TEST(PksImu, NoImuMeansNoImuCriterion) {
  const std::vector<std::pair<MapPointId, Eigen::Vector3d>> none;
  PksSelector s(PksOptions{});
  SelectorInput in = MakeInput(none, SE3d(), 3);
  in.last_keyframe_camera_from_world = SE3d(SO3d(), Eigen::Vector3d(1, 0, 0));
  const auto d = s.Decide(in);
  EXPECT_EQ(d.trace.count("delta_a"), 0u);
  EXPECT_FALSE(d.insert);
}

TEST(SelectorFactory, KnowsEverySelectorAndRejectsUnknownParameters) {
  for (const auto& name : KeyframeSelectorNames()) {
    EXPECT_EQ(MakeKeyframeSelector(name)->name(), name);
  }
  EXPECT_THROW(MakeKeyframeSelector("pks", {{"delat", 20}}), OptionError);
  EXPECT_THROW(MakeKeyframeSelector("nope"), OptionError);
  EXPECT_THROW(MakeKeyframeSelector("pks", {{"delta", -1}}), OptionError);
  EXPECT_NO_THROW(MakeKeyframeSelector("pks", {{"delta", 20}, {"region_width", 5}}));
}

}  // namespace
}  // namespace pkslam
