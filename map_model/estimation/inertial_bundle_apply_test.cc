// Writing inertial bundle adjustments back to a map (map_model/estimation/
// inertial_bundle_collect.h: StartMissingInertialStates, ApplyFullInertialBundle) on keyframes
// along a helix linked by exact IMU preintegrations.
#include <gtest/gtest.h>

#include <vector>

#include "core/util/error.h"
#include "estimators/inertial/inertial_bundle.h"
#include "map_model/estimation/inertial_bundle_collect.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/testing/imu_chain.h"

namespace pkslam {
namespace {

class InertialBundleApplyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = testing::MakeStereoRig(Sensor::kStereoInertial);
    truth_ = testing::MakeHelixChain(&atlas_, rig_, motion_, kNum, ImuBias(), &map_);
  }
  KeyFrame* kf(int k) { return map_.keyframes[k].get(); }
  Map* map() { return kf(0)->map(); }
  void GiveTrueState(const MapWriteLock& lock, int k) {
    InertialState& state = kf(k)->mutable_imu(lock).state;
    state.velocity_world = truth_[k].velocity_world;
    state.valid = true;
  }

  static constexpr int kNum = 10;
  const testing::HelixMotion motion_;
  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticMap map_;
  std::vector<NavState> truth_;
};

TEST_F(InertialBundleApplyTest, KeyframesWithoutAStateStartFromTheirPredecessors) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  EXPECT_EQ(StartMissingInertialStates(lock, kf(kNum - 1)), 0) << "no state to start from";
  for (int k = 0; k <= 5; ++k) GiveTrueState(lock, k);
  EXPECT_EQ(StartMissingInertialStates(lock, kf(kNum - 1)), kNum - 6);
  for (int k = 6; k < kNum; ++k) {
    EXPECT_TRUE(kf(k)->imu().state.valid);
    EXPECT_EQ(kf(k)->imu().state.velocity_world, truth_[5].velocity_world) << "keyframe " << k;
  }
  EXPECT_EQ(StartMissingInertialStates(lock, kf(kNum - 1)), 0) << "nothing left to start";
  lock.unlock();
  EXPECT_THROW(StartMissingInertialStates(lock, kf(kNum - 1)), Error);
}

TEST_F(InertialBundleApplyTest, AFullBundleIsWrittenBackAndMovesTheChangeIndex) {
  InertialBundleOptions options;
  options.iterations_first = 5;
  options.iterations_second = 0;
  InertialBundleProblem problem;
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    for (int k = 0; k < kNum; ++k) GiveTrueState(lock, k);
    map()->mutable_imu_status(lock).imu_initialized = true;
    problem = CollectFullInertialBundle(kf(kNum - 2), options);
  }
  problem.shared_bias = true;
  const InertialBundleResult result = SolveInertialBundle(problem, options);
  ASSERT_FALSE(result.biases.empty());
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  const int changes = map()->NumWorldChanges();
  const int change_index = map()->change_index();
  ApplyFullInertialBundle(lock, map(), *kf(kNum - 2), problem, result);
  EXPECT_EQ(map()->NumWorldChanges(), changes + 1);
  EXPECT_EQ(map()->change_index(), change_index + 1) << "local BA priors become stale";
  EXPECT_EQ(kf(kNum - 1)->imu().state.bias.gyro, result.biases.front().gyro)
      << "the keyframe newer than the problem takes the estimated bias";
  for (int k = 0; k < kNum - 1; ++k) {
    EXPECT_LT((kf(k)->imu().state.velocity_world - truth_[k].velocity_world).norm(), 0.01);
  }
}

}  // namespace
}  // namespace pkslam
