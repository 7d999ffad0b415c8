// Test fixture of loopclosing's tests: the same strip of keyframes visited twice (a loop in one
// map, or a merge when the second visit is built in another map).
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <mutex>
#include <vector>

#include "core/bow/bow_test_utils.h"
#include "map_model/atlas.h"
#include "map_model/keyframe.h"
#include "map_model/keyframe_database.h"
#include "map_model/keyframe_database_test_utils.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"

namespace pkslam::testing {

constexpr int kKeyFrames = 6;

// The same strip of keyframes visited twice: the first visit is "true", the second one's map
// has drifted by `drift` (world_drifted_from_world), and shares no points with the first.
class RevisitTest : public ::testing::Test {
 protected:
  RevisitTest()
      : vocabulary_(testing::MakeRandomVocabulary(10, 4, 5)),
        rig_(MakeStereoRig()),
        scene_(MakeScene(2500, 11, 4.0, 2.5, 3.0, 8.0)),
        poses_(Strip(-0.3, 0.12, kKeyFrames)),
        drift_(SO3d::Exp(Eigen::Vector3d(0.0, 0.03, 0.01)), Eigen::Vector3d(0.12, -0.03, 0.05)) {}

  // Builds the second visit in `map` (drifted) from `scene`.
  std::vector<KeyFramePtr> Revisit(Map* map, const testing::SyntheticScene& scene) {
    auto kfs = AddKeyFrames(&atlas_, map, scene, rig_, poses_, vocabulary_, 100);
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    for (const auto& kf : kfs) {
      for (const auto& mp : kf->map_points()) {
        if (mp && mp->first_keyframe_id() == kf->id())
          mp->SetPosition(lock, drift_ * mp->position());
      }
    }
    for (const auto& kf : kfs) kf->SetPose(lock, kf->camera_from_world() * drift_.Inverse());
    return kfs;
  }

  void Finish(const std::vector<KeyFramePtr>& kfs) {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    for (const auto& kf : kfs) {
      atlas_.database()->Add(lock, kf.get());
      for (const auto& mp : kf->map_points()) {
        if (!mp) continue;
        mp->ComputeDistinctiveDescriptor(lock);
        mp->UpdateNormalAndDepth(lock);
      }
    }
  }

  void SetUp() override {
    atlas_.SetDatabase(std::make_unique<KeyFrameDatabase>(vocabulary_));
    first_ = AddKeyFrames(&atlas_, atlas_.current_map(), scene_, rig_, poses_, vocabulary_, 1);
    Finish(first_);
  }

  Vocabulary vocabulary_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticScene scene_;
  std::vector<SE3d> poses_;
  SE3d drift_;
  Atlas atlas_;
  std::vector<KeyFramePtr> first_;
};

inline double CentreError(const KeyFrame& kf, const SE3d& true_camera_from_world) {
  return (kf.CameraCenter() - true_camera_from_world.Inverse().translation()).norm();
}

}  // namespace pkslam::testing
