#include <gtest/gtest.h>

#include <mutex>

#include "core/sensor/rig_calibration.h"
#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

using testing::MakeForwardPath;
using testing::MakeMap;
using testing::MakeScene;
using testing::MakeStereoRig;

class MapModelTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = MakeStereoRig();
    scene_ = MakeScene(600, 3);
    poses_ = MakeForwardPath(6, 0.15, 4);
    map_ = MakeMap(&atlas_, scene_, rig_, poses_, {});
  }
  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticScene scene_;
  std::vector<SE3d> poses_;
  testing::SyntheticMap map_;
};

TEST_F(MapModelTest, CovisibilityWeightsCountSharedPoints) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  KeyFrame* a = map_.keyframes[0].get();
  KeyFrame* b = map_.keyframes[1].get();
  int shared = 0;
  for (const auto& mp : a->map_points()) {
    if (mp && mp->IsInKeyFrame(b)) ++shared;
  }
  ASSERT_GT(shared, 15);
  EXPECT_EQ(a->Weight(b), shared);
  EXPECT_EQ(b->Weight(a), shared);
  // Ordered by decreasing weight.
  const auto& ordered = a->CovisiblesByWeight();
  for (std::size_t i = 1; i < ordered.size(); ++i) {
    EXPECT_GE(a->Weight(ordered[i - 1]), a->Weight(ordered[i]));
  }
}

TEST_F(MapModelTest, SpanningTreeLinksEveryKeyFrameButTheOrigin) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  EXPECT_EQ(atlas_.current_map()->origin(), map_.keyframes[0].get());
  EXPECT_EQ(map_.keyframes[0]->parent(), nullptr);
  for (std::size_t k = 1; k < map_.keyframes.size(); ++k) {
    ASSERT_NE(map_.keyframes[k]->parent(), nullptr) << k;
    EXPECT_TRUE(map_.keyframes[k]->parent()->children().count(map_.keyframes[k]->id()));
  }
}

TEST_F(MapModelTest, RetiringAKeyFrameReparentsChildrenAndKeepsItsRelativePose) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  Map* map = atlas_.current_map();
  KeyFrame* victim = map_.keyframes[2].get();
  const auto children = victim->children();
  KeyFrame* parent = victim->parent();
  const SE3d expected_relative = victim->camera_from_world() * parent->world_from_camera();
  victim->SetBad(lock);
  EXPECT_TRUE(victim->IsBad());
  EXPECT_EQ(map->keyframes().count(victim->id()), 0u);
  EXPECT_EQ(map->retired_keyframes().count(victim->id()), 1u);
  EXPECT_LT((victim->camera_from_parent().Matrix() - expected_relative.Matrix()).norm(), 1e-12);
  for (const auto& [id, child] : children) {
    ASSERT_NE(child->parent(), nullptr);
    EXPECT_NE(child->parent(), victim);
    EXPECT_FALSE(child->parent()->IsBad());
  }
  for (const auto& kf : map_.keyframes) {
    if (kf.get() == victim) continue;
    EXPECT_EQ(kf->Weight(victim), 0);
  }
  for (const auto& [id, mp] : map->map_points()) EXPECT_FALSE(mp->IsInKeyFrame(victim));
}

TEST_F(MapModelTest, OriginIsNeverRetired) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  map_.keyframes[0]->SetBad(lock);
  EXPECT_FALSE(map_.keyframes[0]->IsBad());
}

TEST_F(MapModelTest, NotEraseDefersRetirement) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  KeyFrame* kf = map_.keyframes[3].get();
  kf->SetNotErase(lock);
  kf->SetBad(lock);
  EXPECT_FALSE(kf->IsBad());
  EXPECT_TRUE(kf->SetErase(lock));
  EXPECT_TRUE(kf->IsBad());
}

TEST_F(MapModelTest, ErasingObservationsMakesAPointBadAtTwoUnits) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  Map* map = atlas_.current_map();
  // A point seen with stereo depth (2 units each) by exactly three keyframes.
  MapPointPtr target;
  for (const auto& mp : map_.point_of_scene_index) {
    if (mp && mp->observations().size() == 3) {
      target = mp;
      break;
    }
  }
  ASSERT_TRUE(target);
  EXPECT_EQ(target->NumObservations(), 6);
  auto erase_first = [&target, &lock]() {
    KeyFrame* kf = target->observations().begin()->second.keyframe;
    kf->EraseMapPointMatch(lock, target->IndexInKeyFrame(kf));
    return std::make_pair(kf, target->EraseObservation(lock, kf));
  };
  EXPECT_FALSE(erase_first().second);  // 4 units left
  EXPECT_EQ(target->NumObservations(), 4);
  KeyFrame* remaining = std::prev(target->observations().end())->second.keyframe;
  EXPECT_TRUE(erase_first().second);  // 2 units left: ORB-SLAM drops it
  EXPECT_TRUE(target->IsBad());
  EXPECT_EQ(map->map_points().count(target->id()), 0u);
  for (const auto& mp : remaining->map_points()) EXPECT_NE(mp, target);
}

// Retiring and fusing change the graph every thread reads: without the write lock they throw
// and leave the map as it was.
TEST_F(MapModelTest, RetiringAndFusingRefuseToRunWithoutTheWriteLock) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  KeyFrame* kf = map_.keyframes[3].get();
  MapPointPtr a, b;
  for (const auto& mp : map_.point_of_scene_index) {
    if (!mp) continue;
    (a ? b : a) = mp;
    if (b) break;
  }
  ASSERT_TRUE(a && b);
  const int points = atlas_.current_map()->NumMapPoints();
  lock.unlock();
  EXPECT_THROW(kf->SetBad(lock), Error);
  EXPECT_THROW(kf->SetErase(lock), Error);
  EXPECT_THROW(a->SetBad(lock), Error);
  EXPECT_THROW(b->Replace(lock, a), Error);
  lock.lock();
  EXPECT_FALSE(kf->IsBad());
  EXPECT_FALSE(a->IsBad());
  EXPECT_FALSE(b->IsBad());
  EXPECT_EQ(atlas_.current_map()->NumMapPoints(), points);
  a->SetBad(lock);
  EXPECT_TRUE(a->IsBad());
  EXPECT_EQ(atlas_.current_map()->NumMapPoints(), points - 1);
}

TEST_F(MapModelTest, ObservationEditsRefuseToRunWithoutTheWriteLock) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  MapPointPtr point;
  for (const auto& mp : map_.point_of_scene_index) {
    // Seen by three keyframes with stereo depth (6 units), not by every keyframe.
    if (mp && mp->observations().size() == 3 && map_.keyframes.size() > 3) {
      point = mp;
      break;
    }
  }
  ASSERT_TRUE(point);
  KeyFrame* observer = point->observations().begin()->second.keyframe;
  KeyFrame* other = nullptr;
  for (const auto& kf : map_.keyframes) {
    if (!point->IsInKeyFrame(kf.get())) other = kf.get();
  }
  ASSERT_NE(other, nullptr);
  const int units = point->NumObservations();
  lock.unlock();
  EXPECT_THROW(point->AddObservation(lock, other, 0), Error);
  EXPECT_THROW(point->EraseObservation(lock, observer), Error);
  lock.lock();
  EXPECT_EQ(point->NumObservations(), units);
  EXPECT_TRUE(point->IsInKeyFrame(observer));
  EXPECT_FALSE(point->IsInKeyFrame(other));
  EXPECT_FALSE(point->EraseObservation(lock, observer));  // 4 units left
  EXPECT_FALSE(point->IsInKeyFrame(observer));
  EXPECT_EQ(point->NumObservations(), units - 2);
}

TEST_F(MapModelTest, MovingKeyFramesAndPointsRefusesToRunWithoutTheWriteLock) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  KeyFrame* kf = map_.keyframes[2].get();
  MapPointPtr point;
  for (const auto& mp : map_.point_of_scene_index) {
    if (mp) {
      point = mp;
      break;
    }
  }
  ASSERT_TRUE(point);
  const SE3d pose = kf->camera_from_world();
  const Eigen::Vector3d position = point->position();
  const SE3d moved = SE3d(SO3d(), Eigen::Vector3d(0.1, 0, 0)) * pose;
  lock.unlock();
  EXPECT_THROW(kf->SetPose(lock, moved), Error);
  EXPECT_THROW(point->SetPosition(lock, position + Eigen::Vector3d::UnitX()), Error);
  const RigSetup setup{kf->rig_ptr(), std::nullopt, std::nullopt};
  EXPECT_THROW(kf->Recalibrate(lock, kf->rig_ptr(), RigWarp(setup, setup), SE3d()), Error);
  lock.lock();
  EXPECT_EQ(kf->camera_from_world().Matrix(), pose.Matrix());
  EXPECT_EQ(point->position(), position);
  kf->SetPose(lock, moved);
  EXPECT_EQ(kf->camera_from_world().Matrix(), moved.Matrix());
  EXPECT_TRUE(kf->world_from_camera().translation().isApprox(moved.Inverse().translation()));
}

TEST_F(MapModelTest, SlotGraphAndPointEditsRefuseToRunWithoutTheWriteLock) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  KeyFrame* kf = map_.keyframes[2].get();
  KeyFrame* other = map_.keyframes[0].get();
  int slot = -1;
  for (int i = 0; i < kf->size() && slot < 0; ++i) {
    if (kf->map_point(i)) slot = i;
  }
  ASSERT_GE(slot, 0);
  const MapPointPtr point = kf->map_point(slot);
  const auto covisibles = kf->CovisiblesByWeight();
  const int weight = kf->Weight(other);
  KeyFrame* parent = kf->parent();
  const auto children = kf->children();
  const Eigen::Vector3d normal = point->normal();
  lock.unlock();
  EXPECT_THROW(kf->AddMapPoint(lock, nullptr, slot), Error);
  EXPECT_THROW(kf->EraseMapPointMatch(lock, slot), Error);
  EXPECT_THROW(kf->EraseMapPointMatch(lock, point.get()), Error);
  EXPECT_THROW(kf->ReplaceMapPointMatch(lock, slot, nullptr), Error);
  EXPECT_THROW(kf->UpdateConnections(lock), Error);
  EXPECT_THROW(kf->AddConnection(lock, other, weight + 100), Error);
  EXPECT_THROW(kf->EraseConnection(lock, other), Error);
  EXPECT_THROW(kf->ChangeParent(lock, other), Error);
  EXPECT_THROW(kf->AddChild(lock, other), Error);
  EXPECT_THROW(kf->EraseChild(lock, other), Error);
  EXPECT_THROW(kf->AddLoopEdge(lock, other), Error);
  EXPECT_THROW(kf->SetNotErase(lock), Error);
  EXPECT_THROW(point->ComputeDistinctiveDescriptor(lock), Error);
  EXPECT_THROW(point->UpdateNormalAndDepth(lock), Error);
  lock.lock();
  EXPECT_EQ(kf->map_point(slot), point);
  EXPECT_EQ(kf->CovisiblesByWeight(), covisibles);
  EXPECT_EQ(kf->Weight(other), weight);
  EXPECT_EQ(kf->parent(), parent);
  EXPECT_EQ(kf->children(), children);
  EXPECT_TRUE(kf->loop_edges().empty());
  EXPECT_EQ(point->normal(), normal);
  kf->EraseMapPointMatch(lock, slot);
  EXPECT_EQ(kf->map_point(slot), nullptr);
}

TEST_F(MapModelTest, ReplaceMovesObservationsToTheSurvivor) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  Map* map = atlas_.current_map();
  MapPointPtr a, b;
  for (const auto& mp : map_.point_of_scene_index) {
    if (!mp) continue;
    if (!a) {
      a = mp;
    } else {
      b = mp;
      break;
    }
  }
  ASSERT_TRUE(a && b);
  const auto a_obs = a->observations();
  b->Replace(lock, a);
  EXPECT_TRUE(b->IsBad());
  EXPECT_EQ(b->replaced_by(), a);
  EXPECT_EQ(map->map_points().count(b->id()), 0u);
  for (const auto& [id, obs] : a_obs) EXPECT_EQ(obs.keyframe->map_point(obs.index), a);
  for (const auto& kf : map_.keyframes) {
    for (const auto& mp : kf->map_points()) EXPECT_NE(mp, b);
  }
}

TEST_F(MapModelTest, DistinctiveDescriptorIsTheMedoid) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  for (const auto& mp : map_.point_of_scene_index) {
    if (!mp) continue;
    // No bit flips in the fixture: every observation has the scene descriptor.
    const auto& obs = mp->observations().begin()->second;
    EXPECT_EQ(mp->descriptor(), obs.keyframe->descriptors()[obs.index]);
  }
}

TEST_F(MapModelTest, PredictScaleIsMonotoneInDistance) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  const MapPointPtr mp = map_.point_of_scene_index[map_.keypoint_points[0][0]];
  ASSERT_TRUE(mp);
  int previous = 100;
  for (double d = mp->min_distance(); d < mp->max_distance(); d += 0.1) {
    const int level = mp->PredictScale(d, rig_->pyramid);
    EXPECT_LE(level, previous);
    previous = level;
  }
}

TEST_F(MapModelTest, ClearBreaksAllLinks) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  std::weak_ptr<KeyFrame> weak_kf = map_.keyframes[1];
  map_.keyframes.clear();
  map_.point_of_scene_index.clear();
  atlas_.ResetCurrentMap(lock);
  EXPECT_TRUE(weak_kf.expired());
  EXPECT_EQ(atlas_.current_map()->NumKeyFrames(), 0);
}

TEST_F(MapModelTest, TheSetOfMapsChangesOnlyUnderThisAtlasWriteLock) {
  Map* first = atlas_.current_map();
  {
    auto not_yet = MapEditor(&atlas_).WriteLater(MapEdit::kFixture);
    EXPECT_THROW(atlas_.CreateNewMap(not_yet), Error);
    EXPECT_THROW(atlas_.ResetCurrentMap(not_yet), Error);
  }
  Atlas other;
  {
    auto lock_of_other = MapEditor(&other).Write(MapEdit::kFixture);
    EXPECT_THROW(atlas_.CreateNewMap(lock_of_other), Error);
    EXPECT_THROW(atlas_.SetCalibration(lock_of_other, {}, {}), Error);
  }
  EXPECT_EQ(atlas_.NumMaps(), 1);
  EXPECT_EQ(atlas_.current_map(), first);
  EXPECT_GT(first->NumKeyFrames(), 0);

  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  Map* second = atlas_.CreateNewMap(lock);
  EXPECT_EQ(atlas_.current_map(), second);
  atlas_.SetCurrentMap(lock, first);
  atlas_.RemoveMap(lock, second);
  EXPECT_EQ(atlas_.NumMaps(), 1);
  EXPECT_EQ(atlas_.current_map(), first);
}

TEST_F(MapModelTest, AMapChangesOnlyUnderTheWriteLock) {
  Map* map = atlas_.current_map();
  const int keyframes = map->NumKeyFrames();
  const int points = map->NumMapPoints();
  const int changes = map->NumWorldChanges();
  const int change_index = map->change_index();
  auto point = std::make_shared<MapPoint>(atlas_.NextMapPointId(), Eigen::Vector3d(0, 0, 5),
                                          map_.keyframes.front().get(), map);
  {
    auto released = MapEditor(&atlas_).Write(MapEdit::kFixture);
    released.unlock();
    EXPECT_THROW(map->AddKeyFrame(released, map_.keyframes.front()), Error);
    EXPECT_THROW(map->AddMapPoint(released, point), Error);
    EXPECT_THROW(map->RecordWorldChange(released, {}), Error);
    EXPECT_THROW(map->IncreaseChangeIndex(released), Error);
    EXPECT_THROW(map->mutable_imu_status(released).imu_initialized = true, Error);
  }
  EXPECT_EQ(map->NumKeyFrames(), keyframes);
  EXPECT_EQ(map->NumMapPoints(), points);
  EXPECT_EQ(map->NumWorldChanges(), changes);
  EXPECT_EQ(map->change_index(), change_index);
  EXPECT_FALSE(map->imu_status().imu_initialized);

  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  map->AddMapPoint(lock, point);
  map->RecordWorldChange(lock, {});
  map->IncreaseChangeIndex(lock);
  EXPECT_EQ(map->NumMapPoints(), points + 1);
  EXPECT_EQ(map->NumWorldChanges(), changes + 1);
  EXPECT_EQ(map->change_index(), change_index + 1);
}

TEST_F(MapModelTest, APointIsBornSeenByItsKeyframesWithADescriptorAndADepthRange) {
  Map* map = atlas_.current_map();
  KeyFrame* a = map_.keyframes[0].get();
  KeyFrame* b = map_.keyframes[1].get();
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  // A keypoint slot freed in each keyframe (their points retired).
  const auto free_slot = [&lock](KeyFrame* kf) {
    for (int i = 0; i < static_cast<int>(kf->map_points().size()); ++i) {
      if (kf->map_point(i)) {
        kf->map_point(i)->SetBad(lock);
        return i;
      }
    }
    return -1;
  };
  const int ia = free_slot(a);
  const int ib = free_slot(b);
  ASSERT_GE(ia, 0);
  ASSERT_GE(ib, 0);
  ASSERT_FALSE(a->map_point(ia));
  const int points = map->NumMapPoints();
  const Eigen::Vector3d position = b->world_from_camera() * Eigen::Vector3d(0.1, -0.2, 4.0);

  {
    auto released = MapEditor(&atlas_).WriteLater(MapEdit::kFixture);
    EXPECT_THROW(map->CreateMapPoint(released, atlas_.NextMapPointId(), position, b, {{a, ia}}),
                 Error);
  }
  EXPECT_FALSE(a->map_point(ia)) << "a refused point takes no slot";

  const MapPointPtr p =
      map->CreateMapPoint(lock, atlas_.NextMapPointId(), position, b, {{a, ia}, {b, ib}});
  EXPECT_EQ(map->NumMapPoints(), points + 1);
  EXPECT_EQ(map->MapPointById(p->id()), p);
  EXPECT_EQ(a->map_point(ia), p);
  EXPECT_EQ(b->map_point(ib), p);
  EXPECT_EQ(p->IndexInKeyFrame(a), ia);
  EXPECT_EQ(p->IndexInKeyFrame(b), ib);
  EXPECT_EQ(p->reference_keyframe(), b);
  EXPECT_EQ(p->NumObservations(), (a->HasDepth(ia) ? 2 : 1) + (b->HasDepth(ib) ? 2 : 1));
  // The medoid of two descriptors is one of them; the range brackets the distance to b.
  EXPECT_TRUE(p->descriptor() == a->descriptors()[ia] || p->descriptor() == b->descriptors()[ib]);
  const double distance = (position - b->world_from_camera().translation()).norm();
  EXPECT_LT(p->min_distance(), distance);
  EXPECT_GT(p->max_distance(), distance);
}

}  // namespace
}  // namespace pkslam
