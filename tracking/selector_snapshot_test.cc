// What the keyframe selector sees of a tracked frame (tracking/selector_snapshot.h), on a
// synthetic stereo map and a frame matched to it.
#include "tracking/selector_snapshot.h"

#include <gtest/gtest.h>

#include <memory>
#include <string_view>
#include <vector>

#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/mapping_backend.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

// A selector that only states what it needs.
class NeedsSelector : public KeyframeSelector {
 public:
  NeedsSelector(bool points, bool outliers) : points_(points), outliers_(outliers) {}
  std::string_view name() const override { return "needs"; }
  bool NeedsTrackedPoints() const override { return points_; }
  bool NeedsOutliers() const override { return outliers_; }
  SelectorDecision Decide(const SelectorInput&) override { return SelectorDecision::No("test"); }

 private:
  bool points_, outliers_;
};

class SelectorSnapshotTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = testing::MakeScene(500, 12, 4.0, 2.5, 1.0, 9.0);
    rig_ = testing::MakeStereoRig();
    const auto path = testing::MakeForwardPath(4, 0.1, 7);
    map_ = testing::MakeMap(&atlas_, scene_, rig_, {path[0], path[1], path[2]}, {});
    std::vector<int> point_of_keypoint;
    frame_ = testing::MakeFrame(scene_, rig_, path[3], 30, 1'500'000'000, {}, &point_of_keypoint);
    frame_.SetPose(path[3]);
    // Matched to the map; every fourth match an outlier of the pose optimisation.
    for (int i = 0; i < frame_.size(); ++i) {
      const MapPointPtr& mp = map_.point_of_scene_index[point_of_keypoint[i]];
      if (!mp) continue;
      frame_.map_points[i] = mp;
      frame_.outliers[i] = matched_++ % 4 == 3 ? 1 : 0;
    }
    view_.rig = rig_.get();
    view_.map = atlas_.current_map();
    view_.frame = &frame_;
    view_.inliers = matched_ - matched_ / 4;
    view_.reference = map_.keyframes[2].get();
    view_.last_keyframe = map_.keyframes[2].get();
    view_.last_relocalisation_frame_id = 7;
  }

  Atlas atlas_;
  testing::SyntheticScene scene_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticMap map_;
  Frame frame_;
  int matched_ = 0;
  TrackedFrameView view_;
};

TEST_F(SelectorSnapshotTest, TheFrameAndItsLastKeyframeAreDescribed) {
  ASSERT_GT(matched_, 100);
  auto lock = MapReader(atlas_).Lock();
  const SelectorInput in = SnapshotTrackedFrame(view_, NeedsSelector(false, false));
  EXPECT_EQ(in.frame_id, 30);
  EXPECT_EQ(in.keyframes_in_map, 3);
  EXPECT_EQ(in.inliers, view_.inliers);
  EXPECT_EQ(in.last_keyframe_id, map_.keyframes[2]->id());
  EXPECT_NEAR(in.SecondsSinceLastKeyFrame(), 1.5 - map_.keyframes[2]->t_ns() * 1e-9, 1e-12);
  EXPECT_EQ(in.last_relocalisation_frame_id, 7);
  EXPECT_GT(in.reference_tracked_points, 100);
  EXPECT_TRUE(in.points.empty()) << "points only for selectors that need them";
  EXPECT_FALSE(in.imu_since_last_frame.has_value()) << "the tracker adds the IMU";
}

TEST_F(SelectorSnapshotTest, CloseKeypointsAreCountedTrackedOrNot) {
  int tracked = 0, untracked = 0;
  for (int i = 0; i < frame_.size(); ++i) {
    const float d = frame_.depth()[i];
    if (d <= 0 || d >= rig_->th_depth) continue;
    (frame_.map_points[i] && !frame_.outliers[i] ? tracked : untracked) += 1;
  }
  ASSERT_GT(tracked, 20);
  ASSERT_GT(untracked, 5) << "outliers and unmatched close keypoints";
  auto lock = MapReader(atlas_).Lock();
  SelectorInput in = SnapshotTrackedFrame(view_, NeedsSelector(false, false));
  EXPECT_EQ(in.tracked_close, tracked);
  EXPECT_EQ(in.untracked_close, untracked);
  auto mono = std::make_shared<CameraRig>(*rig_);
  mono->sensor = Sensor::kMonocular;
  view_.rig = mono.get();
  in = SnapshotTrackedFrame(view_, NeedsSelector(false, false));
  EXPECT_EQ(in.tracked_close + in.untracked_close, 0) << "monocular frames have no depth rule";
}

TEST_F(SelectorSnapshotTest, TrackedPointsComeWithOutliersOnlyWhenAskedFor) {
  auto lock = MapReader(atlas_).Lock();
  const SelectorInput inliers = SnapshotTrackedFrame(view_, NeedsSelector(true, false));
  const SelectorInput all = SnapshotTrackedFrame(view_, NeedsSelector(true, true));
  EXPECT_EQ(static_cast<int>(inliers.points.size()), view_.inliers);
  EXPECT_EQ(static_cast<int>(all.points.size()), matched_);
  int in_last = 0;
  for (const SelectorPoint& p : all.points) {
    const MapPointPtr& mp = frame_.map_points[p.keypoint_index];
    EXPECT_EQ(mp->id(), p.id);
    EXPECT_EQ(p.outlier, frame_.outliers[p.keypoint_index] != 0);
    EXPECT_EQ(p.in_last_keyframe, mp->IsInKeyFrame(map_.keyframes[2].get()));
    in_last += p.in_last_keyframe ? 1 : 0;
  }
  EXPECT_GT(in_last, 0);
  view_.last_keyframe = nullptr;  // e.g. right after a reset
  for (const SelectorPoint& p : SnapshotTrackedFrame(view_, NeedsSelector(true, true)).points) {
    EXPECT_FALSE(p.in_last_keyframe);
  }
  EXPECT_THROW(SnapshotTrackedFrame(TrackedFrameView{}, NeedsSelector(true, true)), Error);
}

// Local mapping as a table of answers.
class ScriptedMapping final : public MappingBackend {
 public:
  bool stopped = false;
  bool initialising = false;
  int queue = 0;
  void InsertKeyFrame(const KeyFramePtr&) override {}
  bool AcceptsKeyFrames() const override { return true; }
  bool IsStoppedOrStopRequested() const override { return stopped; }
  bool IsInitializingImu() const override { return initialising; }
  int QueueSize() const override { return queue; }
  bool QueueFull() const override { return false; }
  void InterruptBundleAdjustment() override {}
  void WaitUntilIdle() override {}
  bool AcceptsKeyFramesAt(std::int64_t) override { return true; }
  bool EmulatesLive() const override { return false; }
  void ResetQueue() override {}
};

// Records what the tracker tells a selector.
class ListeningSelector final : public KeyframeSelector {
 public:
  std::string_view name() const override { return "listening"; }
  SelectorDecision Decide(const SelectorInput&) override { return {}; }
  void OnKeyFrameInserted(const SelectorInput& input) override { inserted.push_back(input); }
  void Reset() override {
    ++resets;
    inserted.clear();
  }
  int resets = 0;
  std::vector<SelectorInput> inserted;
};

TEST(SelectorSnapshotNotes, LocalMappingsStateIsCopiedAsRead) {
  ScriptedMapping mapping;
  mapping.stopped = true;
  mapping.initialising = true;
  mapping.queue = 3;
  SelectorInput in;
  NoteLocalMapping(mapping, /*idle=*/false, &in);
  EXPECT_TRUE(in.local_mapping_stopped);
  EXPECT_FALSE(in.local_mapping_idle);
  EXPECT_TRUE(in.local_mapping_initializing);
  EXPECT_EQ(in.local_mapping_queue, 3);
  mapping.stopped = false;
  NoteLocalMapping(mapping, /*idle=*/true, &in);
  EXPECT_FALSE(in.local_mapping_stopped);
  EXPECT_TRUE(in.local_mapping_idle);
}

TEST(SelectorSnapshotNotes, ANewMapRestartsTheSelectorFromItsFirstFrame) {
  ListeningSelector selector;
  selector.inserted.emplace_back();
  std::vector<int> unused;
  const Frame frame = testing::MakeFrame(testing::MakeScene(50, 2), testing::MakeStereoRig(),
                                         SE3d(), 42, 7'000'000'000, {}, &unused);
  RestartSelector(frame, &selector);
  EXPECT_EQ(selector.resets, 1);
  ASSERT_EQ(selector.inserted.size(), 1u) << "the old state is gone, the new keyframe in";
  EXPECT_EQ(selector.inserted[0].frame_id, 42);
  EXPECT_EQ(selector.inserted[0].t_ns, 7'000'000'000);
}

}  // namespace
}  // namespace pkslam
