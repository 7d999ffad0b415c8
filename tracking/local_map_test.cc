// The tracker's local map (tracking/local_map.h) on a synthetic map: which keyframes and
// points it gathers for a frame, the cap on growing them, and the search by projection.
#include "tracking/local_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <shared_mutex>
#include <vector>

#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

constexpr int kKeyFrames = 8;

class LocalMapTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = testing::MakeStereoRig();
    scene_ = testing::MakeScene(500, 7);
    poses_ = testing::MakeForwardPath(kKeyFrames + 1, 0.2, 5);
    poses_.pop_back();  // the last pose is the new frame's
    map_ = testing::MakeMap(&atlas_, scene_, rig_, poses_, {});
  }
  // A new frame beyond the last keyframe, its pose known; matched to the map points of the
  // scene points `matched` selects (by scene index), or to none.
  Frame NewFrame(const std::function<bool(int)>& matched) {
    const SE3d pose = testing::MakeForwardPath(kKeyFrames + 1, 0.2, 5).back();
    Frame frame = testing::MakeFrame(scene_, rig_, pose, 100, 0, {}, &point_of_keypoint_);
    frame.SetPose(pose);
    for (int i = 0; i < frame.size(); ++i) {
      const MapPointPtr& mp = map_.point_of_scene_index[point_of_keypoint_[i]];
      if (mp && matched(point_of_keypoint_[i])) frame.map_points[i] = mp;
    }
    return frame;
  }
  // How many of the frame's matches each keyframe observes.
  static std::map<KeyFrame*, int> Sharing(const Frame& frame) {
    std::map<KeyFrame*, int> shared;
    for (const auto& mp : frame.map_points) {
      if (!mp) continue;
      for (const auto& [id, obs] : mp->observations()) ++shared[obs.keyframe];
    }
    return shared;
  }

  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticScene scene_;
  std::vector<SE3d> poses_;
  testing::SyntheticMap map_;
  std::vector<int> point_of_keypoint_;
};

TEST_F(LocalMapTest, GathersTheKeyframesSeeingTheMatchesAndNamesTheBestSharer) {
  Frame frame = NewFrame([](int index) { return index % 3 == 0; });
  const std::map<KeyFrame*, int> shared = Sharing(frame);
  ASSERT_GE(shared.size(), 2u);
  int most = 0;
  for (const auto& [kf, n] : shared) most = std::max(most, n);

  LocalMap local(80);
  auto lock = MapReader(atlas_).Lock();
  KeyFrame* best = local.Update(&frame);
  ASSERT_NE(best, nullptr);
  EXPECT_EQ(shared.at(best), most);
  const std::set<KeyFrame*> gathered(local.keyframes().begin(), local.keyframes().end());
  EXPECT_EQ(gathered.size(), local.keyframes().size()) << "a keyframe gathered twice";
  for (const auto& [kf, n] : shared) EXPECT_EQ(gathered.count(kf), 1u) << kf->id();
  // The points are those of the gathered keyframes, each once.
  std::set<MapPointId> expected;
  for (KeyFrame* kf : local.keyframes()) {
    for (const auto& mp : kf->map_points()) {
      if (mp) expected.insert(mp->id());
    }
  }
  std::set<MapPointId> points;
  for (const auto& mp : local.points()) points.insert(mp->id());
  EXPECT_EQ(points, expected);
  EXPECT_EQ(points.size(), local.points().size());
}

TEST_F(LocalMapTest, GrowsByNeighboursOnlyUnderItsCap) {
  // Matches seen only by the last two keyframes: growing adds their covisible neighbours.
  const KeyFrameId first_observer = map_.keyframes[kKeyFrames - 2]->id();
  Frame frame = NewFrame([&](int index) {
    for (const auto& [id, obs] : map_.point_of_scene_index[index]->observations()) {
      if (id < first_observer) return false;
    }
    return true;
  });
  const std::size_t observers = Sharing(frame).size();
  ASSERT_GE(observers, 1u);
  ASSERT_LE(observers, 2u);
  auto lock = MapReader(atlas_).Lock();
  LocalMap capped(0);
  capped.Update(&frame);
  EXPECT_EQ(capped.keyframes().size(), observers);
  LocalMap grown(80);
  grown.Update(&frame);
  EXPECT_GT(grown.keyframes().size(), observers);
  // Each added keyframe is a covisible neighbour, the parent or a child of an observer.
  const std::vector<KeyFrame*>& seen_by = capped.keyframes();
  for (KeyFrame* kf : grown.keyframes()) {
    if (std::find(seen_by.begin(), seen_by.end(), kf) != seen_by.end()) continue;
    const bool related = std::any_of(seen_by.begin(), seen_by.end(), [&](KeyFrame* o) {
      return o->Weight(kf) > 0 || o->parent() == kf || kf->parent() == o;
    });
    EXPECT_TRUE(related) << "keyframe " << kf->id();
  }
}

TEST_F(LocalMapTest, DropsMatchesToRetiredPointsAndKeepsTheLastKeyframesWithoutMatches) {
  Frame frame = NewFrame([](int index) { return index % 2 == 0; });
  int retired_slot = -1;
  for (int i = 0; i < frame.size() && retired_slot < 0; ++i) {
    if (frame.map_points[i]) retired_slot = i;
  }
  ASSERT_GE(retired_slot, 0);
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    frame.map_points[retired_slot]->SetBad(lock);
  }
  auto lock = MapReader(atlas_).Lock();
  LocalMap local(80);
  ASSERT_NE(local.Update(&frame), nullptr);
  EXPECT_EQ(frame.map_points[retired_slot], nullptr);
  const std::vector<KeyFrame*> before = local.keyframes();
  Frame unmatched = NewFrame([](int) { return false; });
  EXPECT_EQ(local.Update(&unmatched), nullptr);
  EXPECT_EQ(local.keyframes(), before);
}

TEST_F(LocalMapTest, SearchMatchesTheProjectedPointsToTheirOwnKeypoints) {
  auto lock = MapReader(atlas_).Lock();
  LocalMap local(80);
  std::vector<KeyFrame*> keyframes;
  for (const auto& kf : map_.keyframes) keyframes.push_back(kf.get());
  std::vector<MapPointPtr> points;
  for (const auto& mp : map_.point_of_scene_index) {
    if (mp) points.push_back(mp);
  }
  local.Reset(keyframes, points);
  Frame frame = NewFrame([](int) { return false; });
  int matchable = 0;
  for (int i = 0; i < frame.size(); ++i) {
    matchable += map_.point_of_scene_index[point_of_keypoint_[i]] != nullptr ? 1 : 0;
  }
  ASSERT_GT(matchable, 50);
  const int found = local.Search(&frame, *rig_, 3.0);
  int right = 0;
  int wrong = 0;
  for (int i = 0; i < frame.size(); ++i) {
    if (!frame.map_points[i]) continue;
    (frame.map_points[i] == map_.point_of_scene_index[point_of_keypoint_[i]] ? right : wrong)++;
  }
  EXPECT_EQ(found, right + wrong);
  EXPECT_GT(right, 0.8 * matchable) << right << " of " << matchable;
  EXPECT_LE(wrong, 0.02 * right);
  // A second search finds nothing new: every point it matched is the frame's now.
  EXPECT_EQ(local.Search(&frame, *rig_, 3.0), 0);
}

}  // namespace
}  // namespace pkslam
