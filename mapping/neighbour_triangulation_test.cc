// New points from a keyframe and its neighbours (mapping/neighbour_triangulation.h), on a
// synthetic monocular map whose last keyframe lost half its points.
#include "mapping/neighbour_triangulation.h"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "core/util/error.h"
#include "core/util/work_meter.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/matching_test_utils.h"

namespace pkslam {
namespace {

class NeighbourTriangulationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = testing::MakeScene(1200, 8);
    vocabulary_ = testing::TrainSceneVocabulary(scene_);
    testing::FrameOptions options;
    options.stereo = false;
    map_ = testing::MakeBowMap(&atlas_, scene_, testing::MakeStereoRig(Sensor::kMonocular),
                               testing::MakeForwardPath(4, 0.25, 5), options, vocabulary_, true);
    // Every other point of the map is dropped: its keypoints are free in every keyframe.
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    for (std::size_t s = 0; s < map_.point_of_scene_index.size(); s += 2) {
      if (!map_.point_of_scene_index[s]) continue;
      map_.point_of_scene_index[s]->SetBad(lock);
      ++dropped_;
    }
    for (const KeyFramePtr& kf : map_.keyframes) kf->UpdateConnections(lock);
  }
  KeyFrame& last() { return *map_.keyframes.back(); }
  int SceneIndex(const KeyFrame* kf, int keypoint) const {
    for (std::size_t k = 0; k < map_.keyframes.size(); ++k) {
      if (map_.keyframes[k].get() == kf) return map_.keypoint_points[k][keypoint];
    }
    return -1;
  }

  Atlas atlas_;
  testing::SyntheticScene scene_;
  Vocabulary vocabulary_;
  testing::SyntheticMap map_;
  int dropped_ = 0;
};

TEST_F(NeighbourTriangulationTest, DroppedPointsAreFoundAgainAtTheirTruePositions) {
  ASSERT_GT(dropped_, 150);
  NeighbourTriangulationOptions options;
  options.monocular = true;
  WorkMeter work;
  options.work = &work;
  std::vector<TriangulatedPoint> found;
  {
    auto lock = MapReader(atlas_).Lock();
    found = TriangulateWithNeighbours(last(), options);
  }
  EXPECT_GT(static_cast<int>(found.size()), dropped_ / 2);
  EXPECT_GT(work.Snapshot()[static_cast<std::size_t>(WorkKind::kTriangulationPair)], 0)
      << "pairs are counted";
  int right = 0;
  for (const TriangulatedPoint& p : found) {
    const int s = SceneIndex(&last(), p.index1);
    ASSERT_EQ(s % 2, 0) << "only keypoints without a point are matched";
    if (s != SceneIndex(p.other, p.index2)) continue;
    ++right;
    EXPECT_LT((p.position - scene_.points_world[s]).norm(), 1e-3);
  }
  EXPECT_GE(right, static_cast<int>(0.98 * found.size()));

  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  const int before = atlas_.current_map()->NumMapPoints();
  const std::vector<MapPointPtr> added = AddTriangulatedPoints(lock, &atlas_, &last(), found);
  EXPECT_EQ(added.size(), found.size());
  EXPECT_EQ(atlas_.current_map()->NumMapPoints(), before + static_cast<int>(found.size()));
  for (const MapPointPtr& mp : added) EXPECT_EQ(mp->NumObservations(), 2);
  EXPECT_TRUE(AddTriangulatedPoints(lock, &atlas_, &last(), found).empty())
      << "slots already filled are not filled twice";
}

TEST_F(NeighbourTriangulationTest, TheSearchStopsWhenAskedAndTheWriteNeedsTheLock) {
  NeighbourTriangulationOptions options;
  options.monocular = true;
  int asked = 0;
  options.stop = [&asked] {
    ++asked;
    return true;
  };
  WorkMeter stopped_work;
  WorkMeter full_work;
  std::vector<TriangulatedPoint> first_only;
  std::vector<TriangulatedPoint> all;
  {
    auto lock = MapReader(atlas_).Lock();
    options.work = &stopped_work;
    first_only = TriangulateWithNeighbours(last(), options);
    options.stop = nullptr;
    options.work = &full_work;
    all = TriangulateWithNeighbours(last(), options);
  }
  constexpr auto kPairs = static_cast<std::size_t>(WorkKind::kTriangulationPair);
  EXPECT_EQ(asked, 1) << "asked before the second neighbour";
  EXPECT_GT(first_only.size(), 0u);
  EXPECT_GE(all.size(), first_only.size());
  for (const TriangulatedPoint& p : first_only) EXPECT_EQ(p.other, first_only[0].other);
  // The stopped search covered one pair (its keypoints counted once), the full one three.
  const std::int64_t one_pair = stopped_work.Snapshot()[kPairs];
  EXPECT_GT(one_pair, 0);
  EXPECT_GT(full_work.Snapshot()[kPairs], 2 * one_pair);
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  lock.unlock();
  EXPECT_THROW(AddTriangulatedPoints(lock, &atlas_, &last(), all), Error);
}

}  // namespace
}  // namespace pkslam
