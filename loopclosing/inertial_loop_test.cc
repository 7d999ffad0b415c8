// Loop closing of inertial maps (IMU initialised, gravity along the world's -z): the loop is
// refused when its correction tilts gravity, otherwise corrected in yaw + translation only, with
// velocities turned and roll/pitch of every keyframe kept.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <mutex>
#include <shared_mutex>

#include "estimators/optim/yaw_manifold.h"
#include "loopclosing/loop_closing.h"
#include "loopclosing/revisit_fixture.h"
#include "map_model/estimation/global_bundle_merge.h"
#include "map_model/map_editor.h"

namespace pkslam {
namespace {

using testing::CentreError;
using testing::kKeyFrames;

struct Snapshot {
  std::map<KeyFrameId, SE3d> camera_from_world;
  std::map<KeyFrameId, Eigen::Vector3d> velocity;
  std::map<KeyFrameId, Eigen::Vector3d> gravity_in_camera;  // GravityInCameras of every map
};

class InertialLoopTest : public testing::RevisitTest {
 protected:
  // The second visit drifted by yaw `yaw` and roll `roll` (rad) and a translation; both visits
  // form one inertial map with a temporal chain and valid velocities.
  // With `merge`, the second visit is a second inertial map of the Atlas.
  void Build(double yaw, double roll, bool merge = false) {
    drift_ = SE3d(SO3d::Exp(Eigen::Vector3d(roll, 0, yaw)), Eigen::Vector3d(0.12, -0.03, 0.05));
    Map* second_map = atlas_.current_map();
    if (merge) {
      auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
      second_map = atlas_.CreateNewMap(lock);
    }
    second_ = Revisit(second_map, scene_);
    Finish(second_);
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    for (Map* map : atlas_.maps()) {
      map->mutable_imu_status(lock).imu_initialized = true;
      map->mutable_imu_status(lock).inertial_ba1_done = true;
      map->mutable_imu_status(lock).inertial_ba2_done = true;
      KeyFrame* previous = nullptr;
      for (const auto& kf : map->keyframes()) {
        if (previous != nullptr) {
          map->inertial_chain().Append(lock, previous, kf.second.get(), std::nullopt);
        }
        kf.second->mutable_imu(lock).state.valid = true;
        kf.second->mutable_imu(lock).state.velocity_world = Eigen::Vector3d(0.4, 0.1, -0.05);
        previous = kf.second.get();
      }
    }
  }

  Snapshot Take() {
    auto lock = MapReader(atlas_).Lock();
    Snapshot s;
    for (const Map* map : atlas_.maps()) {
      for (const auto& [id, kf] : map->keyframes()) {
        s.camera_from_world[id] = kf->camera_from_world();
        s.velocity[id] = kf->imu().state.velocity_world;
      }
      s.gravity_in_camera.merge(GravityInCameras(*map));
    }
    return s;
  }

  LoopClosingStats Close(Sensor sensor) {
    MappingControl control;  // synchronous: never paused
    LoopClosingOptions options;
    options.synchronous = true;
    options.global_ba = false;  // the 4-DoF correction alone
    LoopClosing loop(&atlas_, sensor, control, options);
    loop.Start();
    for (const auto& kf : second_) loop.InsertKeyFrame(kf);
    loop.Finish();
    return loop.stats();
  }

  // Largest change (rad) of a keyframe's view of the world's z axis since `before`.
  double MaxTiltChange(const Snapshot& before) {
    auto lock = MapReader(atlas_).Lock();
    return pkslam::MaxTiltChange(*atlas_.current_map(), before.gravity_in_camera);
  }

  std::vector<KeyFramePtr> second_;
};

TEST_F(InertialLoopTest, CorrectsYawAndTranslationKeepingGravity) {
  Build(0.03, 0.004);  // the loop sees a 0.004 rad roll: under ORB-SLAM3's 0.008 limit
  const Snapshot before = Take();
  const LoopClosingStats stats = Close(Sensor::kStereoInertial);
  ASSERT_EQ(stats.loops.size(), 1u);
  EXPECT_EQ(stats.rejected_inertial, 0);
  EXPECT_LT(MaxTiltChange(before), 1e-9);
  auto lock = MapReader(atlas_).Lock();
  for (int k = 0; k < kKeyFrames; ++k) {
    const KeyFrame& kf = *second_[static_cast<std::size_t>(k)];
    // The yaw and translation drift is gone (what is left: the uncorrected roll over ~1 m).
    EXPECT_LT(CentreError(kf, poses_[static_cast<std::size_t>(k)]), 0.02) << "keyframe " << k;
    const SO3d turn = kf.world_from_camera().so3() * before.camera_from_world.at(kf.id()).so3();
    EXPECT_NEAR(ClosestYawAngle(turn), -0.03, 2e-3);
    EXPECT_LT((kf.imu().state.velocity_world - turn * before.velocity.at(kf.id())).norm(), 1e-9);
  }
  EXPECT_GT(atlas_.current_map()->NumWorldChanges(), 0);  // tracking re-anchors on its keyframe
}

TEST_F(InertialLoopTest, TwoInertialMapsMergeByYawAndTranslation) {
  Build(0.03, 0.004, /*merge=*/true);
  const Snapshot before = Take();
  const LoopClosingStats stats = Close(Sensor::kStereoInertial);
  ASSERT_EQ(stats.merges.size(), 1u);
  auto lock = MapReader(atlas_).Lock();
  EXPECT_EQ(atlas_.NumMaps(), 1);
  EXPECT_LT(MaxTiltChange(before), 1e-9);
  for (int k = 0; k < kKeyFrames; ++k) {
    const KeyFrame& kf = *second_[static_cast<std::size_t>(k)];
    EXPECT_LT(CentreError(kf, poses_[static_cast<std::size_t>(k)]), 0.02) << "keyframe " << k;
    const SO3d turn = kf.world_from_camera().so3() * before.camera_from_world.at(kf.id()).so3();
    EXPECT_LT((kf.imu().state.velocity_world - turn * before.velocity.at(kf.id())).norm(), 1e-9);
  }
}

TEST_F(InertialLoopTest, AVisualMapTakesTheTiltToo) {
  // The same loop in a visual map: the SE3 correction also turns roll (what 4 DoF prevents).
  Build(0.03, 0.004);
  const Snapshot before = Take();
  const LoopClosingStats stats = Close(Sensor::kStereo);
  ASSERT_EQ(stats.loops.size(), 1u);
  EXPECT_GT(MaxTiltChange(before), 0.003);
}

TEST_F(InertialLoopTest, RefusesALoopThatTiltsGravity) {
  Build(0.03, 0.03);
  const Snapshot before = Take();
  const LoopClosingStats stats = Close(Sensor::kStereoInertial);
  EXPECT_TRUE(stats.loops.empty());
  EXPECT_GE(stats.rejected_inertial, 1);
  auto lock = MapReader(atlas_).Lock();
  for (const auto& [id, kf] : atlas_.current_map()->keyframes()) {
    EXPECT_EQ(kf->camera_from_world().Matrix(), before.camera_from_world.at(id).Matrix());
  }
}

// A second visit "drifted" by 1.5 m over a path of about a metre: what a repeating place a
// texture period away looks like to verification. Stereo and stereo-inertial maps are metric,
// so such a jump is refused (bound 0.3 m + 5% of the path); the map stays as it was.
class DriftBoundTest : public InertialLoopTest {
 protected:
  void ExpectRefused(Sensor sensor) {
    drift_ = SE3d(SO3d::Exp(Eigen::Vector3d(0, 0, 0.01)), Eigen::Vector3d(1.5, 0.0, 0.0));
    second_ = Revisit(atlas_.current_map(), scene_);
    Finish(second_);
    if (IsInertial(sensor)) {
      auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
      atlas_.current_map()->mutable_imu_status(lock).imu_initialized = true;
      atlas_.current_map()->mutable_imu_status(lock).inertial_ba2_done = true;
    }
    const Snapshot before = Take();
    const LoopClosingStats stats = Close(sensor);
    EXPECT_TRUE(stats.loops.empty());
    EXPECT_GE(stats.rejected_implausible, 1);
    auto lock = MapReader(atlas_).Lock();
    for (const auto& [id, kf] : atlas_.current_map()->keyframes()) {
      EXPECT_EQ(kf->camera_from_world().Matrix(), before.camera_from_world.at(id).Matrix());
    }
  }
};

TEST_F(DriftBoundTest, StereoRefusesAJumpFarBeyondTheDriftBound) { ExpectRefused(Sensor::kStereo); }

TEST_F(DriftBoundTest, StereoInertialRefusesAJumpFarBeyondTheDriftBound) {
  ExpectRefused(Sensor::kStereoInertial);
}

TEST_F(DriftBoundTest, MonocularMapsHaveNoMetricBound) {
  // The same jump in a visual monocular map is a plausible scale/translation drift: corrected.
  drift_ = SE3d(SO3d::Exp(Eigen::Vector3d(0, 0, 0.01)), Eigen::Vector3d(1.5, 0.0, 0.0));
  second_ = Revisit(atlas_.current_map(), scene_);
  Finish(second_);
  const LoopClosingStats stats = Close(Sensor::kMonocular);
  EXPECT_EQ(stats.rejected_implausible, 0);
}

}  // namespace
}  // namespace pkslam
