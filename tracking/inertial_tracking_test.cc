// The inertial side of tracking (tracking/inertial_tracking.h) on exact IMU samples of a helix
// and a synthetic stereo map seen along it (camera = body).
#include "tracking/inertial_tracking.h"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "imu/imu_test_utils.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

constexpr std::int64_t kKeyFrameStepNs = 50'000'000;  // MakeMap's keyframe spacing

class InertialTrackingTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = testing::MakeStereoRig(Sensor::kStereoInertial);
    rig_->imu = ImuNoise();
    // Points in front of the camera at 0.1 s, in the world.
    scene_ = testing::MakeScene(600, 3);
    for (Eigen::Vector3d& p : scene_.points_world) p = Truth(2).world_from_body * p;
    // Keyframes at 0 and 50 ms (MakeMap's times) at their true poses.
    map_ = testing::MakeMap(&atlas_, scene_, rig_, {CameraFromWorld(0), CameraFromWorld(1)}, {});
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    InertialState& state = keyframe()->mutable_imu(lock).state;
    state.velocity_world = Truth(1).velocity_world;
    state.valid = true;
    tracking_.samples().Add(testing::SampleImu(motion_, 0, 6 * kKeyFrameStepNs, 5'000'000,
                                               ImuBias(), *rig_->imu, nullptr));
  }
  NavState Truth(int step) const { return motion_.State(0.05 * step); }
  SE3d CameraFromWorld(int step) const { return Truth(step).world_from_body.Inverse(); }
  KeyFrame* keyframe() { return map_.keyframes[1].get(); }
  // The frame at `step` (no pose), its keypoints matched to the map's points.
  Frame FrameAt(int step) const {
    std::vector<int> point_of_keypoint;
    Frame frame = testing::MakeFrame(scene_, rig_, CameraFromWorld(step), 10 + step,
                                     step * kKeyFrameStepNs, {}, &point_of_keypoint);
    for (int i = 0; i < frame.size(); ++i) {
      frame.map_points[i] = map_.point_of_scene_index[point_of_keypoint[i]];
    }
    return frame;
  }
  static double PositionError(const Frame& frame, const NavState& truth) {
    return (frame.camera_from_world().Inverse().translation() - truth.world_from_body.translation())
        .norm();
  }

  const testing::HelixMotion motion_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticScene scene_;
  Atlas atlas_;
  testing::SyntheticMap map_;
  InertialTracking tracking_{ImuNoise()};
  PoseOptimizerOptions pose_options_;
};

TEST_F(InertialTrackingTest, AFrameIsPredictedFromTheLastKeyframe) {
  Frame current = FrameAt(2);
  tracking_.Preintegrate(ImuBias(), keyframe()->t_ns(), &current);
  EXPECT_FALSE(current.imu.from_last_frame.has_value()) << "no frame before";
  auto lock = MapReader(atlas_).Lock();
  ASSERT_TRUE(tracking_.Predict(Frame(), keyframe(), *rig_, &current));
  EXPECT_LT(PositionError(current, Truth(2)), 1e-4);
  EXPECT_LT((current.imu.state.velocity_world - Truth(2).velocity_world).norm(), 1e-3);
  EXPECT_TRUE(current.imu.state.valid);
  EXPECT_FALSE(tracking_.Predict(Frame(), nullptr, *rig_, &current)) << "no anchor";
}

TEST_F(InertialTrackingTest, AfterAnOptimisationTheNextFrameIsPredictedFromIt) {
  auto lock = MapReader(atlas_).Lock();
  Frame current = FrameAt(2);
  tracking_.Preintegrate(ImuBias(), keyframe()->t_ns(), &current);
  ASSERT_TRUE(tracking_.Predict(Frame(), keyframe(), *rig_, &current));
  current.outliers.assign(current.size(), 0);
  tracking_.OptimizePose(Frame(), keyframe(), *rig_, pose_options_, &current);
  EXPECT_LT(PositionError(current, Truth(2)), 1e-3);

  Frame next = FrameAt(3);
  tracking_.Preintegrate(current.imu.state.bias, keyframe()->t_ns(), &next);
  ASSERT_TRUE(next.imu.from_last_frame.has_value());
  EXPECT_NEAR(next.imu.from_last_frame->dt, 0.05, 1e-12);
  // A keyframe velocity 1 m/s off would put a keyframe-based prediction 10 cm off: the
  // prediction from the optimised last frame does not use it.
  lock.unlock();
  {
    auto write = MapEditor(&atlas_).Write(MapEdit::kFixture);
    keyframe()->mutable_imu(write).state.velocity_world += Eigen::Vector3d(1, 0, 0);
  }
  lock.lock();
  ASSERT_TRUE(tracking_.Predict(current, keyframe(), *rig_, &next));
  EXPECT_LT(PositionError(next, Truth(3)), 2e-3);

  // After a change to the map's world the keyframe is the anchor again.
  lock.unlock();
  {
    auto write = MapEditor(&atlas_).Write(MapEdit::kFixture);
    tracking_.Follow(*atlas_.current_map());  // the first look at the map
    atlas_.current_map()->RecordWorldChange(write, {});
    EXPECT_TRUE(tracking_.Follow(*atlas_.current_map()).changed);
  }
  lock.lock();
  ASSERT_TRUE(tracking_.Predict(current, keyframe(), *rig_, &next));
  EXPECT_GT(PositionError(next, Truth(3)), 0.05);
}

TEST_F(InertialTrackingTest, ANewKeyframeTakesTheFramesStateAndJoinsTheChain) {
  Frame current = FrameAt(2);
  tracking_.Preintegrate(ImuBias(), keyframe()->t_ns(), &current);
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  Map* map = atlas_.current_map();
  current.SetPose(CameraFromWorld(2));
  auto with_state = std::make_shared<KeyFrame>(atlas_.NextKeyFrameId(), current, map);
  map->AddKeyFrame(lock, with_state);
  ImuBias bias;
  bias.gyro = Eigen::Vector3d(0.01, 0, 0);
  current.imu.state.bias = bias;
  current.imu.state.valid = true;
  tracking_.Attach(lock, current, keyframe(), with_state.get());
  EXPECT_EQ(with_state->imu().previous(), keyframe());
  ASSERT_TRUE(with_state->imu().from_previous.has_value());
  EXPECT_NEAR(with_state->imu().from_previous->dt, 0.05, 1e-12);
  EXPECT_EQ(with_state->imu().state.bias.gyro, bias.gyro);

  // Without an estimated state it starts from its predecessor's bias.
  Frame later = FrameAt(3);
  later.SetPose(CameraFromWorld(3));
  auto without = std::make_shared<KeyFrame>(atlas_.NextKeyFrameId(), later, map);
  map->AddKeyFrame(lock, without);
  tracking_.Attach(lock, later, with_state.get(), without.get());
  EXPECT_FALSE(without->imu().state.valid);
  EXPECT_EQ(without->imu().state.bias.gyro, bias.gyro);
  EXPECT_EQ(with_state->imu().next(), without.get());
}

TEST_F(InertialTrackingTest, TheSelectorSeesTheBodysOwnAccelerationOnceGravityIsKnown) {
  Frame last = FrameAt(2);
  Frame current = FrameAt(3);
  tracking_.Preintegrate(ImuBias(), 0, &last);
  EXPECT_FALSE(tracking_.IntervalSinceLastFrame(last, std::nullopt).has_value());
  tracking_.Preintegrate(ImuBias(), 0, &current);
  const auto plain = tracking_.IntervalSinceLastFrame(current, std::nullopt);
  ASSERT_TRUE(plain.has_value());
  EXPECT_NEAR(plain->dt, 0.05, 1e-12);
  EXPECT_FALSE(plain->mean_accel_world_no_gravity.has_value());
  const auto world = tracking_.IntervalSinceLastFrame(current, Truth(2).world_from_body.so3());
  ASSERT_TRUE(world->mean_accel_world_no_gravity.has_value());
  // The helix's acceleration over the 50 ms, against the value mid-interval.
  EXPECT_LT((*world->mean_accel_world_no_gravity - motion_.Acceleration(0.125)).norm(), 0.1);
}

TEST_F(InertialTrackingTest, TheSelectorsIntervalTakesTheLastBodysOrientationOnceReady) {
  Frame last = FrameAt(2);
  last.SetPose(CameraFromWorld(2));
  Frame current = FrameAt(3);
  tracking_.Preintegrate(ImuBias(), 0, &last);
  tracking_.Preintegrate(ImuBias(), 0, &current);
  SelectorInput before_ready;
  tracking_.FillSelectorInput(current, last, *rig_, /*map_ready=*/false, &before_ready);
  ASSERT_TRUE(before_ready.imu_since_last_frame.has_value());
  EXPECT_FALSE(before_ready.imu_since_last_frame->mean_accel_world_no_gravity.has_value());
  SelectorInput ready;
  tracking_.FillSelectorInput(current, last, *rig_, /*map_ready=*/true, &ready);
  const SO3d world_from_body =
      (last.camera_from_world().Inverse() * rig_->body_from_camera.Inverse()).so3();
  const auto expected = tracking_.IntervalSinceLastFrame(current, world_from_body);
  ASSERT_TRUE(ready.imu_since_last_frame->mean_accel_world_no_gravity.has_value());
  EXPECT_TRUE(ready.imu_since_last_frame->mean_accel_world_no_gravity->isApprox(
      *expected->mean_accel_world_no_gravity, 1e-12));
}

TEST_F(InertialTrackingTest, TheIntegrationBiasIsTheLastFramesElseTheKeyframesElseZero) {
  Frame last = FrameAt(2);
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  keyframe()->mutable_imu(lock).state.bias.gyro = Eigen::Vector3d(0.01, 0, 0);
  EXPECT_TRUE(InertialTracking::IntegrationBias(last, nullptr).gyro.isZero());
  EXPECT_EQ(InertialTracking::IntegrationBias(last, keyframe()).gyro.x(), 0.01);
  last.imu.state.valid = true;
  last.imu.state.bias.gyro = Eigen::Vector3d(0, 0.02, 0);
  EXPECT_EQ(InertialTracking::IntegrationBias(last, keyframe()).gyro.y(), 0.02);
}

TEST_F(InertialTrackingTest, AFrameIsCarriedIntoARotatedAndRescaledWorld) {
  Frame frame = FrameAt(2);
  frame.SetPose(CameraFromWorld(2));
  frame.imu.state.velocity_world = Eigen::Vector3d(0.3, -0.2, 0.1);
  const Eigen::Vector3d centre = frame.camera_from_world().Inverse().translation();
  WorldChange change;
  change.kind = WorldChange::Kind::kTransform;
  change.rotation = SO3d::Exp(Eigen::Vector3d(0.1, -0.2, 0.3));
  change.scale = 1.5;
  const Eigen::Vector3d direction =
      frame.camera_from_world().so3().Inverse() * Eigen::Vector3d::UnitZ();
  InertialTracking::CarryAcross(change, &frame);
  const SE3d world_from_camera = frame.camera_from_world().Inverse();
  EXPECT_TRUE(world_from_camera.translation().isApprox(1.5 * (change.rotation * centre), 1e-12));
  EXPECT_TRUE((world_from_camera.so3() * Eigen::Vector3d::UnitZ())
                  .isApprox(change.rotation * direction, 1e-12))
      << "the viewing direction turns with the world";
  EXPECT_TRUE(frame.imu.state.velocity_world.isApprox(
      1.5 * (change.rotation * Eigen::Vector3d(0.3, -0.2, 0.1)), 1e-12));
}

TEST_F(InertialTrackingTest, AWorldChangeMovesTheCurrentFrameTheRecordsAndTheMotionModel) {
  TrackedFrames frames;
  frames.current = FrameAt(2);
  frames.current.SetPose(CameraFromWorld(2));
  frames.velocity = SE3d(SO3d(), Eigen::Vector3d(0.1, 0.2, 0.3));
  FrameRecords records;
  FrameRecord record;
  record.reference = map_.keyframes[1];
  record.camera_from_reference = SE3d(SO3d(), Eigen::Vector3d(0.04, 0, 0));
  records.Add(record);
  const Eigen::Vector3d centre = frames.current.camera_from_world().Inverse().translation();
  // A second tracker that does not carry its current frame across.
  InertialTracking other{ImuNoise()};
  TrackedFrames kept = frames;
  FrameRecords kept_records = records;

  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  Map& map = *atlas_.current_map();
  tracking_.FollowMap(map, true, &frames, &records);  // the first look: nothing to move
  other.FollowMap(map, false, &kept, &kept_records);
  EXPECT_TRUE(frames.current.camera_from_world().Inverse().translation().isApprox(centre));
  EXPECT_EQ(frames.velocity->translation(), Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(records.back().camera_from_reference.translation(), Eigen::Vector3d(0.04, 0, 0));

  WorldChange change;
  change.kind = WorldChange::Kind::kTransform;
  change.rotation = SO3d::Exp(Eigen::Vector3d(0.1, -0.2, 0.3));
  change.scale = 2.0;
  map.RecordWorldChange(lock, change);
  tracking_.FollowMap(map, true, &frames, &records);
  other.FollowMap(map, false, &kept, &kept_records);
  EXPECT_TRUE(frames.current.camera_from_world().Inverse().translation().isApprox(
      2.0 * (change.rotation * centre), 1e-12));
  EXPECT_TRUE(frames.velocity->translation().isApprox(Eigen::Vector3d(0.2, 0.4, 0.6), 1e-12));
  EXPECT_TRUE(records.back().camera_from_reference.translation().isApprox(
      Eigen::Vector3d(0.08, 0, 0), 1e-12));
  EXPECT_TRUE(kept.current.camera_from_world().Inverse().translation().isApprox(centre))
      << "without correct_current the frame stays in the world it was tracked in";
  EXPECT_TRUE(kept.velocity->translation().isApprox(Eigen::Vector3d(0.2, 0.4, 0.6), 1e-12));
}

TEST_F(InertialTrackingTest, ThePreintegrationKeepsTheSamplesTheOldestAnchorNeeds) {
  // The last keyframe (50 ms) is the oldest anchor: samples from it on stay, older ones go.
  TrackedFrames frames;
  frames.current = FrameAt(4);
  frames.last_kf = map_.keyframes[1];
  tracking_.PreintegrateCurrent(ImuBias(), nullptr, &frames);
  const std::int64_t now = frames.current.t_ns();
  EXPECT_TRUE(tracking_.samples().Between(frames.last_kf->t_ns(), now, ImuBias()).has_value());
  EXPECT_FALSE(tracking_.samples().Between(0, now, ImuBias()).has_value());
  // A monocular map's first frame at 0 s, older than the keyframe, keeps the samples from it.
  InertialTracking starting{ImuNoise()};
  starting.samples().Add(testing::SampleImu(motion_, 0, 6 * kKeyFrameStepNs, 5'000'000, ImuBias(),
                                            *rig_->imu, nullptr));
  const Frame first = FrameAt(0);
  TrackedFrames pair = frames;
  starting.PreintegrateCurrent(ImuBias(), &first, &pair);
  EXPECT_TRUE(starting.samples().Between(0, now, ImuBias()).has_value());
}

}  // namespace
}  // namespace pkslam
