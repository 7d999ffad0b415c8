// The keyframe side of a tracked frame (tracking/keyframe_inserter.h), on a synthetic stereo map
// with BoW: the decision with local mapping's backpressure, and a new keyframe joining the map,
// local mapping and the selector.
#include "tracking/keyframe_inserter.h"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/matching_test_utils.h"

namespace pkslam {
namespace {

// Records the keyframes handed over; its queue can be full.
class RecordingMapping final : public MappingBackend {
 public:
  bool full = false;
  std::vector<KeyFramePtr> inserted;
  int waits = 0;
  void InsertKeyFrame(const KeyFramePtr& kf) override { inserted.push_back(kf); }
  bool AcceptsKeyFrames() const override { return true; }
  bool IsStoppedOrStopRequested() const override { return false; }
  bool IsInitializingImu() const override { return false; }
  int QueueSize() const override { return full ? 2 : 0; }
  bool QueueFull() const override { return full; }
  void InterruptBundleAdjustment() override {}
  void WaitUntilIdle() override { ++waits; }
  bool AcceptsKeyFramesAt(std::int64_t) override { return true; }
  bool EmulatesLive() const override { return false; }
  void ResetQueue() override {}
};

// Always asks for a keyframe; records what it is told after insertion.
class InsertingSelector final : public KeyframeSelector {
 public:
  bool after_creation = false;
  std::vector<SelectorInput> decided;
  std::vector<SelectorInput> inserted;
  std::string_view name() const override { return "inserting"; }
  bool SnapshotAfterCreation() const override { return after_creation; }
  SelectorDecision Decide(const SelectorInput& input) override {
    decided.push_back(input);
    SelectorDecision decision;
    decision.insert = true;
    decision.reason = "always";
    return decision;
  }
  void OnKeyFrameInserted(const SelectorInput& input) override { inserted.push_back(input); }
};

class KeyFrameInserterTest : public ::testing::Test {
 protected:
  KeyFrameInserterTest() {
    // The current frame a little past the newest keyframe, posed, with every other keypoint
    // matched to its map point (so it has close keypoints without a point).
    std::vector<int> point_of_keypoint;
    testing::FrameOptions options;
    options.pixel_noise = 0.5;
    options.seed = 90;
    const SE3d pose =
        SE3d(SO3d::Exp(Eigen::Vector3d(0, 0.01, 0)), Eigen::Vector3d(0.03, 0, 0)) * bow_.poses[3];
    frames_.current = testing::MakeFrame(bow_.scene, bow_.rig, pose, 80, 4'000'000'000, options,
                                         &point_of_keypoint);
    frames_.current.SetPose(pose);
    for (int i = 0; i < frames_.current.size(); i += 2) {
      const MapPointPtr& mp = bow_.map.point_of_scene_index[point_of_keypoint[i]];
      frames_.current.map_points[i] = mp;
      frames_.inliers += mp != nullptr;
    }
    frames_.current.outliers.assign(frames_.current.size(), 0);
    frames_.reference_kf = bow_.map.keyframes[3];
    frames_.last_kf = bow_.map.keyframes[3];
    context_.rig = bow_.rig.get();
    context_.imu_ready = [] { return false; };
    context_.attach = [this](const MapWriteLock&, KeyFrame*, KeyFrame* previous, const Frame&) {
      attached_after_.push_back(previous);
    };
  }
  KeyFrameInserter MakeInserter() {
    return KeyFrameInserter(&bow_.atlas, &bow_.vocabulary, &selector_, &mapping_, options_,
                            /*monocular=*/false);
  }
  SelectorInput Decide(KeyFrameInserter* inserter, bool* declined) {
    auto lock = MapReader(bow_.atlas).Lock();
    return inserter->Decide(context_, frames_, /*mapping_idle=*/true, declined);
  }
  int KeyFrames() {
    auto lock = MapReader(bow_.atlas).Lock();
    return bow_.atlas.current_map()->NumKeyFrames();
  }

  testing::StereoBowMap bow_{800, 31, 4, 12};
  TrackingOptions options_;
  RecordingMapping mapping_;
  InsertingSelector selector_;
  TrackedFrames frames_;
  KeyFrameContext context_;
  std::vector<KeyFrame*> attached_after_;  // the inertial link's `previous`, per keyframe
};

TEST_F(KeyFrameInserterTest, AnInsertedKeyFrameJoinsTheMapLocalMappingAndTheSelector) {
  KeyFrameInserter inserter = MakeInserter();
  bool declined = false;
  const SelectorInput input = Decide(&inserter, &declined);
  ASSERT_NE(inserter.DecisionFor(frames_.current.id()), nullptr);
  ASSERT_TRUE(inserter.DecisionFor(frames_.current.id())->insert);
  EXPECT_FALSE(declined);
  EXPECT_EQ(input.frame_id, frames_.current.id());
  EXPECT_EQ(input.inliers, frames_.inliers);
  EXPECT_TRUE(input.local_mapping_idle);
  EXPECT_EQ(input.last_keyframe_id, bow_.map.keyframes[3]->id());
  ASSERT_GT(input.untracked_close, 0);

  const int keyframes = KeyFrames();
  const KeyFramePtr kf = inserter.Insert(context_, input, &frames_);
  ASSERT_TRUE(kf);
  EXPECT_EQ(KeyFrames(), keyframes + 1);
  EXPECT_EQ(frames_.last_kf, kf);
  EXPECT_EQ(frames_.reference_kf, kf);
  EXPECT_EQ(frames_.current.reference_kf, kf);
  EXPECT_EQ(attached_after_, std::vector<KeyFrame*>{bow_.map.keyframes[3].get()})
      << "the keyframe is linked after the newest one";
  ASSERT_EQ(mapping_.inserted.size(), 1u);
  EXPECT_EQ(mapping_.inserted[0], kf);
  EXPECT_EQ(mapping_.waits, 0) << "no lockstep asked";
  ASSERT_EQ(selector_.inserted.size(), 1u);
  EXPECT_EQ(selector_.inserted[0].tracked_close, input.tracked_close)
      << "the selector is told the input it decided on";
  // The keyframe brought close points of its own (stereo), beyond the frame's matches.
  int points = 0;
  for (const MapPointPtr& mp : kf->map_points()) points += mp != nullptr;
  EXPECT_GT(points, frames_.inliers);
}

TEST_F(KeyFrameInserterTest, ASelectorAskingForTheKeyFramesViewSeesItsNewPoints) {
  selector_.after_creation = true;
  options_.lockstep = true;
  KeyFrameInserter inserter = MakeInserter();
  bool declined = false;
  const SelectorInput input = Decide(&inserter, &declined);
  inserter.Insert(context_, input, &frames_);
  ASSERT_EQ(selector_.inserted.size(), 1u);
  const SelectorInput& created = selector_.inserted[0];
  EXPECT_GT(created.tracked_close, input.tracked_close);
  EXPECT_LT(created.untracked_close, input.untracked_close);
  EXPECT_EQ(created.local_mapping_idle, input.local_mapping_idle);
  EXPECT_EQ(mapping_.waits, 1) << "lockstep waits for local mapping";
}

TEST_F(KeyFrameInserterTest, AFullQueueTurnsTheKeyFrameDownAndSaysSo) {
  mapping_.full = true;
  KeyFrameInserter inserter = MakeInserter();
  inserter.EnableTrace(true);
  bool declined = false;
  Decide(&inserter, &declined);
  ASSERT_EQ(selector_.decided.size(), 1u) << "the selector still decides";
  ASSERT_NE(inserter.DecisionFor(frames_.current.id()), nullptr);
  EXPECT_FALSE(inserter.DecisionFor(frames_.current.id())->insert);
  EXPECT_TRUE(declined);
  ASSERT_EQ(inserter.trace().size(), 1u);
  EXPECT_EQ(inserter.trace()[0].frame_id, frames_.current.id());
  EXPECT_FALSE(inserter.trace()[0].decision.insert);
}

TEST_F(KeyFrameInserterTest, ADecisionBelongsToTheFrameItWasMadeFor) {
  KeyFrameInserter inserter = MakeInserter();
  EXPECT_EQ(inserter.DecisionFor(frames_.current.id()), nullptr) << "nothing decided yet";
  bool declined = false;
  Decide(&inserter, &declined);
  EXPECT_NE(inserter.DecisionFor(frames_.current.id()), nullptr);
  // The next frame, tracked without a decision (localisation mode switched on at run time),
  // must not act on this one's: it would insert, interrupt local BA and count its reasons again.
  EXPECT_EQ(inserter.DecisionFor(frames_.current.id() + 1), nullptr);
}

}  // namespace
}  // namespace pkslam
