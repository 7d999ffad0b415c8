#include "map_model/estimation/global_bundle_merge.h"

#include <gtest/gtest.h>

#include <mutex>
#include <shared_mutex>

#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

using testing::FrameOptions;
using testing::MakeForwardPath;
using testing::MakeFrame;
using testing::MakeMap;
using testing::MakeScene;
using testing::MakeStereoRig;

// A global BA "result" that moves the whole world by `world_change` (what a BA does to a map
// whose gauge it does not fix, and a convenient exact answer for the write-back).
BundleResult MoveWorld(const BundleProblem& problem, const SE3d& world_change) {
  BundleResult r;
  for (const auto& k : problem.keyframes) {
    r.camera_from_world.push_back(k.camera_from_world * world_change.Inverse());
  }
  for (const auto& p : problem.points) r.points_world.push_back(world_change * p.position_world);
  return r;
}

class MergeGlobalBundleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = MakeStereoRig();
    scene_ = MakeScene(600, 5);
    poses_ = MakeForwardPath(6, 0.2, 6);
    map_ = MakeMap(&atlas_, scene_, rig_, poses_, FrameOptions{});
    auto lock = MapReader(atlas_).Lock();
    problem_ = CollectGlobalBundle(lock, *atlas_.current_map());
  }

  // A keyframe created "while the BA ran": child of `parent`, posed `ahead` metres further.
  KeyFramePtr AddKeyFrame(const MapWriteLock& lock, KeyFrame* parent, double ahead) {
    Map* map = atlas_.current_map();
    const SE3d pose = SE3d(SO3d(), Eigen::Vector3d(0, 0, -ahead)) * parent->camera_from_world();
    std::vector<int> unused;
    Frame frame = MakeFrame(scene_, rig_, pose, atlas_.NextFrameId(), 0, FrameOptions{}, &unused);
    frame.SetPose(pose);
    auto kf = std::make_shared<KeyFrame>(atlas_.NextKeyFrameId(), frame, map);
    map->AddKeyFrame(lock, kf);
    kf->ChangeParent(lock, parent);
    return kf;
  }

  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticScene scene_;
  std::vector<SE3d> poses_;
  Atlas atlas_;
  testing::SyntheticMap map_;
  BundleProblem problem_;
};

TEST_F(MergeGlobalBundleTest, ProblemKeyframesAndPointsTakeTheOptimisedValues) {
  const SE3d change(SO3d::Exp(Eigen::Vector3d(0.0, 0.05, 0.0)), Eigen::Vector3d(0.3, 0, 0.1));
  const BundleResult result = MoveWorld(problem_, change);
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  const int change_index = atlas_.current_map()->change_index();
  MergeGlobalBundle(lock, atlas_.current_map(), problem_, result);
  for (std::size_t k = 0; k < problem_.keyframes.size(); ++k) {
    const SE3d& got =
        atlas_.current_map()->KeyFrameById(problem_.keyframes[k].keyframe_id)->camera_from_world();
    // The fixed gauge keyframe keeps its pose.
    const SE3d& expected = problem_.keyframes[k].fixed ? problem_.keyframes[k].camera_from_world
                                                       : result.camera_from_world[k];
    EXPECT_LT((got.translation() - expected.translation()).norm(), 1e-9);
  }
  for (std::size_t p = 0; p < problem_.points.size(); ++p) {
    EXPECT_LT((atlas_.current_map()->MapPointById(problem_.points[p].point_id)->position() -
               result.points_world[p])
                  .norm(),
              1e-9);
  }
  EXPECT_EQ(atlas_.current_map()->change_index(), change_index + 1);
}

TEST_F(MergeGlobalBundleTest, NewKeyframesFollowTheirParentAndNewPointsTheirReference) {
  KeyFramePtr a;
  KeyFramePtr b;
  MapPointPtr point;
  SE3d a_before;
  SE3d b_before;
  Eigen::Vector3d point_before;
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    a = AddKeyFrame(lock, map_.keyframes.back().get(), 0.2);
    b = AddKeyFrame(lock, a.get(), 0.2);  // a chain of two new keyframes
    point_before = b->world_from_camera() * Eigen::Vector3d(0.1, -0.2, 4.0);
    point = std::make_shared<MapPoint>(atlas_.NextMapPointId(), point_before, b.get(),
                                       atlas_.current_map());
    atlas_.current_map()->AddMapPoint(lock, point);
    a_before = a->camera_from_world();
    b_before = b->camera_from_world();
  }
  const SE3d change(SO3d::Exp(Eigen::Vector3d(0.02, -0.04, 0.01)), Eigen::Vector3d(-0.2, 0.1, 0));
  const BundleResult result = MoveWorld(problem_, change);
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  MergeGlobalBundle(lock, atlas_.current_map(), problem_, result);
  // The whole world moved by `change`: so must the keyframes and the point the BA never saw.
  const SE3d a_expected = a_before * change.Inverse();
  const SE3d b_expected = b_before * change.Inverse();
  EXPECT_LT((a->camera_from_world().translation() - a_expected.translation()).norm(), 1e-9);
  EXPECT_LT((b->camera_from_world().translation() - b_expected.translation()).norm(), 1e-9);
  EXPECT_LT((a->camera_from_world().so3().Inverse() * a_expected.so3()).Log().norm(), 1e-9);
  EXPECT_LT((point->position() - change * point_before).norm(), 1e-9);
}

TEST_F(MergeGlobalBundleTest, KeyframesOfAnotherMapAreLeftAlone) {
  // A new keyframe that moved to another map (e.g. a merge) before the write-back.
  KeyFramePtr moved;
  SE3d before;
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    moved = AddKeyFrame(lock, map_.keyframes.back().get(), 0.2);
    Map* other = atlas_.CreateNewMap(lock);
    atlas_.SetCurrentMap(lock, map_.keyframes.front()->map());
    moved->set_map(other);
    before = moved->camera_from_world();
  }
  const SE3d change(SO3d(), Eigen::Vector3d(1.0, 0, 0));
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  MergeGlobalBundle(lock, map_.keyframes.front()->map(), problem_, MoveWorld(problem_, change));
  EXPECT_LT((moved->camera_from_world().translation() - before.translation()).norm(), 1e-12);
}

}  // namespace
}  // namespace pkslam
