// Duplicate points fused between a keyframe and its neighbours (mapping/neighbour_fusion.h),
// on a synthetic stereo map where the last keyframe saw some points as new ones.
#include "mapping/neighbour_fusion.h"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "core/util/error.h"
#include "core/util/work_meter.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

class NeighbourFusionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    map_ = testing::MakeMap(&atlas_, testing::MakeScene(400, 9), testing::MakeStereoRig(),
                            testing::MakeForwardPath(4, 0.1, 6), {});
    // In the last keyframe, every fifth of its points is replaced by a duplicate seen only by
    // it (as if it had been triangulated anew): same position and descriptor.
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    KeyFrame* kf = map_.keyframes.back().get();
    Map* map = atlas_.current_map();
    int n = 0;
    for (int i = 0; i < static_cast<int>(kf->map_points().size()); ++i) {
      const MapPointPtr original = kf->map_point(i);
      if (!original || original->IsBad() || n++ % 5 != 0) continue;
      original->EraseObservation(lock, kf);
      kf->EraseMapPointMatch(lock, i);
      auto copy =
          std::make_shared<MapPoint>(atlas_.NextMapPointId(), original->position(), kf, map);
      copy->AddObservation(lock, kf, i);
      kf->AddMapPoint(lock, copy, i);
      copy->ComputeDistinctiveDescriptor(lock);
      copy->UpdateNormalAndDepth(lock);
      map->AddMapPoint(lock, copy);
      pairs_.push_back({original, copy, i});
    }
    for (const KeyFramePtr& k : map_.keyframes) k->UpdateConnections(lock);
  }

  struct Duplicate {
    MapPointPtr original, copy;
    int index;
  };
  Atlas atlas_;
  testing::SyntheticMap map_;
  std::vector<Duplicate> pairs_;
};

TEST_F(NeighbourFusionTest, DuplicatesMergeIntoTheBetterObservedPoint) {
  ASSERT_GT(pairs_.size(), 20u);
  const int points_before = atlas_.current_map()->NumMapPoints();
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  KeyFrame* kf = map_.keyframes.back().get();
  WorkMeter work;
  NeighbourFusionOptions options;
  options.work = &work;
  EXPECT_EQ(FuseWithNeighbours(lock, kf, options), 3) << "fused with the three others";
  EXPECT_GT(work.Snapshot()[static_cast<std::size_t>(WorkKind::kFuseProjection)], 0);
  int merged = 0;
  for (const Duplicate& d : pairs_) {
    if (!d.copy->IsBad()) continue;
    ++merged;
    EXPECT_FALSE(d.original->IsBad()) << "the point the neighbours observe survives";
    EXPECT_EQ(kf->map_point(d.index), d.original);
    EXPECT_TRUE(d.original->IsInKeyFrame(kf));
  }
  EXPECT_GE(merged, static_cast<int>(0.9 * pairs_.size()));
  EXPECT_EQ(atlas_.current_map()->NumMapPoints(), points_before - merged);
}

TEST_F(NeighbourFusionTest, ARetiredKeyframeFusesNothingAndTheLockIsRequired) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  KeyFrame* kf = map_.keyframes.back().get();
  lock.unlock();
  EXPECT_THROW(FuseWithNeighbours(lock, kf, {}), Error);
  lock.lock();
  kf->SetBad(lock);
  EXPECT_EQ(FuseWithNeighbours(lock, kf, {}), 0);
  for (const Duplicate& d : pairs_) EXPECT_FALSE(d.original->IsBad());
}

}  // namespace
}  // namespace pkslam
