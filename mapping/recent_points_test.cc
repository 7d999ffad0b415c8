// The probation of new map points (mapping/recent_points.h) on a synthetic stereo map.
#include "mapping/recent_points.h"

#include <gtest/gtest.h>

#include <memory>

#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

class RecentPointsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    map_ = testing::MakeMap(&atlas_, testing::MakeScene(300, 5), testing::MakeStereoRig(),
                            testing::MakeForwardPath(5, 0.1, 3), {});
    // Free keypoint slots (with depth) in every keyframe for the points the tests create.
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    int freed = 0;
    for (const MapPointPtr& mp : map_.point_of_scene_index) {
      if (mp && freed++ < 60) mp->SetBad(lock);
    }
  }
  // A new point created at keyframe `first`, observed by keyframes first..first+observers-1
  // at an unused keypoint slot (stereo keypoints: each observation counts twice).
  MapPointPtr NewPoint(const MapWriteLock& lock, int first, int observers) {
    KeyFrame* reference = map_.keyframes[first].get();
    auto mp = std::make_shared<MapPoint>(atlas_.NextMapPointId(), Eigen::Vector3d(0, 0, 5),
                                         reference, atlas_.current_map());
    for (int k = first; k < first + observers; ++k) {
      KeyFrame* kf = map_.keyframes[k].get();
      for (int i = 0; i < static_cast<int>(kf->map_points().size()); ++i) {
        if (kf->map_point(i) || kf->right_u()[i] < 0) continue;
        mp->AddObservation(lock, kf, i);
        kf->AddMapPoint(lock, mp, i);
        break;
      }
    }
    EXPECT_EQ(mp->NumObservations(), 2 * observers) << "stereo observations count twice";
    atlas_.current_map()->AddMapPoint(lock, mp);
    return mp;
  }
  KeyFrameId Id(int k) const { return map_.keyframes[k]->id(); }

  Atlas atlas_;
  testing::SyntheticMap map_;
  RecentPoints recent_;
  RecentPointRule rule_;  // found ratio 0.25, 3 observation units
};

TEST_F(RecentPointsTest, APointSeldomFoundWhereExpectedIsRetiredAtOnce) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  const MapPointPtr seldom = NewPoint(lock, 0, 3);
  const MapPointPtr often = NewPoint(lock, 0, 3);
  seldom->IncreaseVisible(4);  // found 1 of 5: 0.2
  often->IncreaseVisible(3);   // found 1 of 4: 0.25, not below
  recent_.Watch(seldom);
  recent_.Watch(often);
  EXPECT_EQ(recent_.Cull(lock, Id(0), rule_), 1);
  EXPECT_TRUE(seldom->IsBad());
  EXPECT_FALSE(often->IsBad());
  EXPECT_EQ(recent_.size(), 1u);
}

TEST_F(RecentPointsTest, TwoKeyframesLaterAPointNeedsMoreThanTheMinimumObservations) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  const MapPointPtr lonely = NewPoint(lock, 0, 1);  // 2 units
  const MapPointPtr shared = NewPoint(lock, 0, 2);  // 4 units
  recent_.Watch(lonely);
  recent_.Watch(shared);
  EXPECT_EQ(recent_.Cull(lock, Id(1), rule_), 0) << "one keyframe old: still on probation";
  EXPECT_EQ(recent_.size(), 2u);
  EXPECT_EQ(recent_.Cull(lock, Id(2), rule_), 1);
  EXPECT_TRUE(lonely->IsBad());
  EXPECT_FALSE(shared->IsBad());
  EXPECT_EQ(recent_.size(), 1u);
  EXPECT_EQ(recent_.Cull(lock, Id(3), rule_), 0);
  EXPECT_EQ(recent_.size(), 0u) << "three keyframes old: probation over";
  EXPECT_FALSE(shared->IsBad());
  // Monocular maps (one unit per observation) ask for more than 2: a point seen twice by
  // stereo keyframes (4 units) would pass, one seen once (2 units) would not.
  RecentPointRule monocular = rule_;
  monocular.min_observations = 2;
  const MapPointPtr once = NewPoint(lock, 2, 1);
  const MapPointPtr twice = NewPoint(lock, 2, 2);
  recent_.Watch(once);
  recent_.Watch(twice);
  EXPECT_EQ(recent_.Cull(lock, Id(4), monocular), 1);
  EXPECT_TRUE(once->IsBad());
  EXPECT_FALSE(twice->IsBad());
}

TEST_F(RecentPointsTest, PointsRetiredElsewhereLeaveUncountedAndTheLockIsRequired) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  const MapPointPtr fused = NewPoint(lock, 0, 1);
  recent_.Watch(fused);
  fused->SetBad(lock);  // e.g. fused into another point
  EXPECT_EQ(recent_.Cull(lock, Id(4), rule_), 0);
  EXPECT_EQ(recent_.size(), 0u);
  recent_.Watch(NewPoint(lock, 0, 1));
  lock.unlock();
  EXPECT_THROW(recent_.Cull(lock, Id(4), rule_), Error);
}

}  // namespace
}  // namespace pkslam
