#include "map_model/estimation/inertial_init_collect.h"

#include <gtest/gtest.h>

#include <mutex>
#include <vector>

#include "core/util/error.h"
#include "imu/imu_test_utils.h"
#include "imu/preintegration.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/imu_chain.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

using testing::HelixMotion;
using testing::kTestGravity;

// Keyframes every 50 ms (MakeMap's spacing) at their true poses on the helix (camera = body),
// linked by exact IMU preintegrations at `bias`; no inertial states yet.
class InertialInitCollectTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = testing::MakeStereoRig(Sensor::kStereoInertial);
    truth_ = testing::MakeHelixChain(&atlas_, rig_, motion_, kNum, bias_, &map_);
  }
  KeyFrame* kf(int k) { return map_.keyframes[k].get(); }

  static constexpr int kNum = 8;
  const HelixMotion motion_;
  const ImuBias bias_{Eigen::Vector3d(0.003, -0.002, 0.001), Eigen::Vector3d(0.05, -0.03, 0.02)};
  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticMap map_;
  std::vector<NavState> truth_;
};

TEST_F(InertialInitCollectTest, ChainRunsThroughTheKeyFramesLinkedAfter) {
  auto lock = MapReader(atlas_).Lock();
  const std::vector<KeyFrame*> chain = InertialChainThrough(kf(3));
  ASSERT_EQ(chain.size(), static_cast<std::size_t>(kNum));
  for (int k = 0; k < kNum; ++k) EXPECT_EQ(chain[k], kf(k));
}

TEST_F(InertialInitCollectTest, ChainStopsWhereTheLinkBreaks) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  kf(6)->mutable_imu(lock).from_previous.reset();  // an IMU gap before keyframe 6
  const std::vector<KeyFrame*> chain = InertialChainThrough(kf(3));
  ASSERT_EQ(chain.size(), 6u);
  EXPECT_EQ(chain.front(), kf(0));
  EXPECT_EQ(chain.back(), kf(5));
  // From the other side of the gap the chain starts at 6.
  const std::vector<KeyFrame*> after = InertialChainThrough(kf(7));
  ASSERT_EQ(after.size(), 2u);
  EXPECT_EQ(after.front(), kf(6));
}

TEST_F(InertialInitCollectTest, PropagatedVelocitiesFollowTheImu) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  // Metric = 2 * map units: the chain's velocities are in map units, so are the predictions.
  const double scale = 2.0;
  for (int k = 0; k <= 3; ++k) {
    kf(k)->mutable_imu(lock).state.velocity_world = truth_[k].velocity_world / scale;
    kf(k)->mutable_imu(lock).state.valid = true;
  }
  // Keyframe 6 already has an estimate (tracking's): the propagation stops before it.
  kf(6)->mutable_imu(lock).state.velocity_world = Eigen::Vector3d(9, 9, 9);
  kf(6)->mutable_imu(lock).state.valid = true;
  EXPECT_EQ(PropagateVelocities(lock, kf(3), bias_, kTestGravity, scale), 2);
  for (int k = 4; k <= 5; ++k) {
    ASSERT_TRUE(kf(k)->imu().state.valid);
    EXPECT_LT((scale * kf(k)->imu().state.velocity_world - truth_[k].velocity_world).norm(), 0.01)
        << "keyframe " << k;
  }
  EXPECT_EQ(kf(6)->imu().state.velocity_world, Eigen::Vector3d(9, 9, 9));
  EXPECT_FALSE(kf(7)->imu().state.valid);
  // Nothing to do from a keyframe without a state.
  EXPECT_EQ(PropagateVelocities(lock, kf(7), bias_, kTestGravity, scale), 0);
}

TEST_F(InertialInitCollectTest, AStageIsCollectedOnlyWhenItsRuleHolds) {
  auto lock = MapReader(atlas_).Lock();
  InertialInitRule rule;
  rule.min_keyframes = kNum;
  rule.min_time_s = 0.05 * (kNum - 1);
  const auto problem = CollectInertialInit(kf(3), rule);
  ASSERT_TRUE(problem.has_value());
  EXPECT_EQ(problem->chain.size(), static_cast<std::size_t>(kNum));
  EXPECT_EQ(problem->newest.get(), kf(kNum - 1)) << "through the keyframes tracking added";
  ASSERT_EQ(problem->keyframes.size(), static_cast<std::size_t>(kNum));
  EXPECT_EQ(problem->preintegrations.size(), static_cast<std::size_t>(kNum - 1));
  EXPECT_EQ(problem->keyframes[2].t_ns, kf(2)->t_ns());
  EXPECT_NEAR(problem->preintegrations[0].dt, 0.05, 1e-12);

  InertialInitRule more = rule;
  more.min_keyframes = kNum + 1;
  EXPECT_FALSE(CollectInertialInit(kf(3), more).has_value()) << "too few keyframes";
  more = rule;
  more.min_time_s = 0.05 * kNum;
  EXPECT_FALSE(CollectInertialInit(kf(3), more).has_value()) << "too short";
  double travel = 0;
  for (int k = 1; k < kNum; ++k)
    travel += (kf(k)->CameraCenter() - kf(k - 1)->CameraCenter()).norm();
  more = rule;
  more.min_travel = 1.01 * travel;
  EXPECT_FALSE(CollectInertialInit(kf(3), more).has_value()) << "too little travel (monocular)";
  more.min_travel = 0.99 * travel;
  EXPECT_TRUE(CollectInertialInit(kf(3), more).has_value());
}

TEST_F(InertialInitCollectTest, AResultRotatesAndScalesTheWholeMapAndTellsTracking) {
  InertialInitProblem problem;
  {
    auto lock = MapReader(atlas_).Lock();
    InertialInitRule rule;
    rule.min_keyframes = 3;
    rule.min_time_s = 0;
    problem = *CollectInertialInit(kf(kNum - 1), rule);
  }
  InertialInitResult result;
  result.success = true;
  result.world_from_gravity = SO3d::Exp(Eigen::Vector3d(0.1, -0.05, 0.3));
  result.scale = 2.0;
  result.bias = bias_;
  result.gravity_world = result.world_from_gravity * Eigen::Vector3d(0, 0, -9.81);
  for (int k = 0; k < kNum; ++k) result.velocities_world.push_back(Eigen::Vector3d(k, 0, 0));
  const Eigen::Vector3d centre_before = kf(4)->CameraCenter();
  const MapPointPtr point = kf(4)->GoodMapPoints().front();
  const Eigen::Vector3d point_before = point->position();
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  Map* map = kf(0)->map();
  const int changes = map->NumWorldChanges();
  ApplyInertialInit(lock, map, problem, result, /*refinement=*/false, kf(4)->t_ns());
  const SO3d new_from_old = result.world_from_gravity.Inverse();
  EXPECT_LT((kf(4)->CameraCenter() - 2.0 * (new_from_old * centre_before)).norm(), 1e-9);
  EXPECT_LT((point->position() - 2.0 * (new_from_old * point_before)).norm(), 1e-9);
  EXPECT_LT(
      (kf(4)->imu().state.velocity_world - 2.0 * (new_from_old * Eigen::Vector3d(4, 0, 0))).norm(),
      1e-12);
  for (int k = 0; k < kNum; ++k) {
    EXPECT_TRUE(kf(k)->imu().state.valid);
    EXPECT_EQ(kf(k)->imu().state.bias.accel, bias_.accel);
  }
  EXPECT_TRUE(map->imu_status().imu_initialized);
  EXPECT_EQ(map->imu_status().imu_init_t_ns, kf(4)->t_ns());
  ASSERT_EQ(map->NumWorldChanges(), changes + 1);
  EXPECT_EQ(map->world_change(changes).kind, WorldChange::Kind::kTransform);
  EXPECT_DOUBLE_EQ(map->world_change(changes).scale, 2.0);
  lock.unlock();
  EXPECT_THROW(ApplyInertialInit(lock, map, problem, result, true, 0), Error);
}

}  // namespace
}  // namespace pkslam
