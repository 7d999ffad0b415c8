// KeyFrameSteps (mapping/keyframe_steps.h): local mapping's work on one keyframe, in order, on a
// synthetic stereo map whose last keyframe lost every other point and is 3 cm off its pose.
#include "mapping/keyframe_steps.h"

#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <vector>

#include "core/util/work_meter.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/matching_test_utils.h"

namespace pkslam {
namespace {

constexpr double kPoseErrorM = 0.03;

class KeyFrameStepsTest : public ::testing::Test {
 protected:
  KeyFrameStepsTest() : fixture_(1200, 21, 5, 4) {
    auto lock = MapEditor(&fixture_.atlas).Write(MapEdit::kFixture);
    for (std::size_t s = 0; s < fixture_.map.point_of_scene_index.size(); s += 2) {
      if (!fixture_.map.point_of_scene_index[s]) continue;
      fixture_.map.point_of_scene_index[s]->SetBad(lock);
      ++dropped_;
    }
    for (const KeyFramePtr& kf : fixture_.map.keyframes) kf->UpdateConnections(lock);
    last().SetPose(lock, SE3d(SO3d(), Eigen::Vector3d(kPoseErrorM, 0, 0)) * fixture_.poses.back());
  }

  KeyFrame& last() { return *fixture_.map.keyframes.back(); }
  double LastPoseError() {
    auto lock = MapReader(fixture_.atlas).Lock();
    return (last().camera_from_world().translation() - fixture_.poses.back().translation()).norm();
  }
  int NumMapPoints() {
    auto lock = MapReader(fixture_.atlas).Lock();
    return fixture_.atlas.current_map()->NumMapPoints();
  }

  // Steps whose hooks count their calls; `waiting`: a newer keyframe is queued.
  std::unique_ptr<KeyFrameSteps> MakeSteps(bool waiting, bool stopping = false) {
    LocalMappingOptions options;
    options.cull_keyframes = false;
    KeyFrameStepHooks hooks;
    hooks.keyframe_waiting = [this, waiting] {
      ++waiting_asked_;
      return waiting;
    };
    hooks.stopping = [stopping] { return stopping; };
    hooks.step_boundary = [this] { ++boundaries_; };
    hooks.pace = [this] { ++paced_; };
    hooks.abort = &abort_;
    hooks.work = &work_;
    return std::make_unique<KeyFrameSteps>(&fixture_.atlas, fixture_.rig, options,
                                           std::move(hooks));
  }

  testing::StereoBowMap fixture_;
  int dropped_ = 0;
  int waiting_asked_ = 0;
  int boundaries_ = 0;
  int paced_ = 0;
  std::atomic<bool> abort_{false};
  WorkMeter work_;
};

TEST_F(KeyFrameStepsTest, TheStepsFindLostPointsAgainAndAdjustTheKeyFrame) {
  ASSERT_GT(dropped_, 100);
  const int points_before = NumMapPoints();
  const KeyFrameStepReport report =
      MakeSteps(/*waiting=*/false)->Run(fixture_.map.keyframes.back());
  EXPECT_GT(report.points_created, dropped_ / 4);
  EXPECT_GT(NumMapPoints(), points_before);
  // Local BA ran, was not aborted, and took the keyframe back towards its true pose.
  EXPECT_GT(report.ba_ms, 0.0);
  EXPECT_FALSE(report.ba_aborted);
  EXPECT_FALSE(report.inertial_ba);
  EXPECT_LT(LastPoseError(), kPoseErrorM / 5);
  EXPECT_EQ(report.keyframes_culled, 0);  // culling is off
  // A boundary before the first step, the fusion, the BA and the culling; pacing before each
  // write-back of a computed result (the new points, the BA).
  EXPECT_EQ(boundaries_, 4);
  EXPECT_EQ(paced_, 2);
  EXPECT_GT(work_.Snapshot()[static_cast<std::size_t>(WorkKind::kSolverResidual)], 0);
}

TEST_F(KeyFrameStepsTest, ANewerKeyFrameLeavesFusionAndTheAdjustmentToIt) {
  const int points_before = NumMapPoints();
  const KeyFrameStepReport report = MakeSteps(/*waiting=*/true)->Run(fixture_.map.keyframes.back());
  // Triangulation asks before its second neighbour and stops: the first one's points only.
  EXPECT_GT(report.points_created, 0);
  EXPECT_EQ(NumMapPoints(), points_before + report.points_created);  // no fusion merged any
  EXPECT_EQ(report.ba_ms, 0.0);
  EXPECT_NEAR(LastPoseError(), kPoseErrorM, 1e-9);  // no BA moved it
  EXPECT_EQ(boundaries_, 3);
  EXPECT_EQ(work_.Snapshot()[static_cast<std::size_t>(WorkKind::kSolverResidual)], 0);
  EXPECT_GE(waiting_asked_, 3);  // triangulation, fusion, adjustment
}

TEST_F(KeyFrameStepsTest, AStopRequestLeavesTheAdjustmentOut) {
  const KeyFrameStepReport report =
      MakeSteps(/*waiting=*/false, /*stopping=*/true)->Run(fixture_.map.keyframes.back());
  EXPECT_GT(report.points_created, dropped_ / 4);  // all neighbours searched
  EXPECT_EQ(report.ba_ms, 0.0);
  EXPECT_NEAR(LastPoseError(), kPoseErrorM, 1e-9);
  EXPECT_EQ(boundaries_, 3);
}

}  // namespace
}  // namespace pkslam
