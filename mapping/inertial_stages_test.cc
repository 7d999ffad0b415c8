// InertialStages on a helix chain with exact IMU: the initialisation waits for its chain, then
// recovers the gyro bias; the refinement waits while a calibration adjustment solves.
#include "mapping/inertial_stages.h"

#include <gtest/gtest.h>

#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/testing/imu_chain.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

class InertialStagesTest : public ::testing::Test {
 protected:
  InertialStagesTest() {
    options_.min_keyframes = 10;
    options_.min_time_stereo_s = 0.4;
    options_.viba1_s = 0.1;  // clock time since the initialisation (viba_motion_time off)
    options_.viba2_s = 10.0;
  }

  // The chain: `n` keyframes every 50 ms, all already in the map (tracking runs ahead).
  void MakeChain(int n) {
    auto rig = testing::MakeStereoRig(Sensor::kStereoInertial);
    testing::MakeHelixChain(&atlas_, rig, testing::HelixMotion(), n, kBias, &map_);
  }

  InertialStages Stages() {
    InertialStageHooks hooks;
    hooks.keyframe_queued = [] { return false; };
    hooks.calibration_running = [this] { return calibration_running_; };
    return InertialStages(&atlas_, Sensor::kStereoInertial, options_, 1, std::move(hooks));
  }

  MapImuStatus Status() {
    auto lock = MapReader(atlas_).Lock();
    return map_.keyframes.front()->map()->imu_status();
  }

  const ImuBias kBias{Eigen::Vector3d(0.003, -0.002, 0.001), Eigen::Vector3d::Zero()};
  Atlas atlas_;
  testing::SyntheticMap map_;
  InertialMappingOptions options_;
  bool calibration_running_ = false;
};

TEST_F(InertialStagesTest, TheInitialisationWaitsForItsChain) {
  MakeChain(6);  // 6 keyframes over 0.25 s: too few, too short
  InertialStages stages = Stages();
  stages.Step(map_.keyframes.back());
  EXPECT_FALSE(Status().imu_initialized);
  EXPECT_FALSE(stages.initializing());
  EXPECT_TRUE(stages.stats().imu_stages.empty());
}

TEST_F(InertialStagesTest, TheInitialisationFindsTheGyroBiasOverTheWholeChain) {
  MakeChain(16);
  InertialStages stages = Stages();
  stages.Step(map_.keyframes[12]);  // the chain ends at the newest keyframe, 15
  EXPECT_TRUE(Status().imu_initialized);
  EXPECT_FALSE(Status().inertial_ba1_done);
  EXPECT_FALSE(stages.initializing());
  const auto snapshots = stages.stats().imu_stages;
  ASSERT_EQ(snapshots.size(), 1u);
  EXPECT_EQ(snapshots[0].stage, 0);
  EXPECT_EQ(snapshots[0].world_from_body.size(), 16u);
  EXPECT_LT((snapshots[0].bias.gyro - kBias.gyro).norm(), 5e-4)
      << snapshots[0].bias.gyro.transpose();
}

TEST_F(InertialStagesTest, TheRefinementWaitsWhileACalibrationAdjustmentSolves) {
  MakeChain(16);
  InertialStages stages = Stages();
  stages.Step(map_.keyframes[12]);
  ASSERT_TRUE(Status().imu_initialized);
  calibration_running_ = true;
  stages.Step(map_.keyframes[15]);  // 0.15 s after the initialisation: VIBA1 is due
  EXPECT_FALSE(Status().inertial_ba1_done);
  EXPECT_EQ(stages.stats().imu_stages.size(), 1u);
  calibration_running_ = false;
  stages.Step(map_.keyframes[15]);
  EXPECT_TRUE(Status().inertial_ba1_done);
  const auto snapshots = stages.stats().imu_stages;
  ASSERT_EQ(snapshots.size(), 2u);
  EXPECT_EQ(snapshots[1].stage, 1);
}

}  // namespace
}  // namespace pkslam
