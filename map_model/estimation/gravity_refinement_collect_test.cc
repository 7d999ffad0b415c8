// The map side of the gravity refinement (map_model/estimation/gravity_refinement_collect.h) on
// keyframes along a helix linked by exact IMU preintegrations, with their true states.
#include "map_model/estimation/gravity_refinement_collect.h"

#include <gtest/gtest.h>

#include <vector>

#include "core/util/error.h"
#include "estimators/inertial/inertial_bundle.h"
#include "imu/imu_test_utils.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/testing/imu_chain.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

class GravityRefinementTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = testing::MakeStereoRig(Sensor::kStereoInertial);
    truth_ = testing::MakeHelixChain(&atlas_, rig_, motion_, kNum, ImuBias(), &map_);
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    for (int k = 0; k < kNum; ++k) {
      InertialState& state = kf(k)->mutable_imu(lock).state;
      state.velocity_world = truth_[k].velocity_world;
      state.valid = true;
    }
    map()->mutable_imu_status(lock).imu_initialized = true;
    options_.gravity_magnitude = 9.81;
  }
  KeyFrame* kf(int k) { return map_.keyframes[k].get(); }
  Map* map() { return kf(0)->map(); }

  static constexpr int kNum = 40;  // 2 s of the helix: the body turns about two axes
  const testing::HelixMotion motion_;
  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticMap map_;
  std::vector<NavState> truth_;
  InertialBundleOptions options_;
};

TEST_F(GravityRefinementTest, ARefinementIsDueOnlyOnceTheChainTurnedEnough) {
  auto lock = MapReader(atlas_).Lock();
  GravityRefinementRule rule;
  rule.min_observability = 0;
  rule.step = 0.01;
  const auto problem = CollectGravityRefinement(kf(kNum - 2), rule, options_);
  ASSERT_TRUE(problem.has_value());
  EXPECT_GT(problem->observability, 0) << problem->observability;
  EXPECT_EQ(problem->bundle.edges.size(), static_cast<std::size_t>(kNum - 2));
  EXPECT_EQ(problem->change_index, map()->change_index());

  GravityRefinementRule strict = rule;
  strict.min_observability = problem->observability + 0.01;
  EXPECT_FALSE(CollectGravityRefinement(kf(kNum - 2), strict, options_).has_value());
  strict = rule;
  strict.max_keyframes = kNum - 2;
  EXPECT_FALSE(CollectGravityRefinement(kf(kNum - 2), strict, options_).has_value())
      << "a chain longer than max_keyframes";
  lock.unlock();
  {
    auto write = MapEditor(&atlas_).Write(MapEdit::kFixture);
    map()->mutable_imu_status(write).gravity_refinement_observability = problem->observability;
  }
  lock.lock();
  EXPECT_FALSE(CollectGravityRefinement(kf(kNum - 2), rule, options_).has_value())
      << "not `step` more than at the last refinement";
}

TEST_F(GravityRefinementTest, ASolvedRefinementIsMergedAndTrackingIsTold) {
  std::optional<GravityRefinementProblem> problem;
  {
    auto lock = MapReader(atlas_).Lock();
    GravityRefinementRule rule;
    rule.min_observability = 0;
    rule.step = 0;
    problem = CollectGravityRefinement(kf(kNum - 2), rule, options_);
  }
  ASSERT_TRUE(problem.has_value());
  options_.iterations_first = 5;
  options_.iterations_second = 0;
  const InertialBundleResult result = SolveInertialBundle(problem->bundle, options_);
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  const int changes = map()->NumWorldChanges();
  const double tilt = ApplyGravityRefinement(lock, map(), *kf(kNum - 2), *problem, result);
  EXPECT_LT(tilt, 1e-3) << "exact data: gravity stays where it is";
  EXPECT_EQ(map()->NumWorldChanges(), changes + 1);
  EXPECT_DOUBLE_EQ(map()->imu_status().gravity_refinement_observability, problem->observability);
  EXPECT_EQ(kf(kNum - 1)->imu().state.bias.accel, kf(kNum - 2)->imu().state.bias.accel)
      << "the keyframe tracked meanwhile continues from the new bias";
  for (int k = 0; k < kNum - 1; ++k) {
    EXPECT_LT((kf(k)->CameraCenter() - truth_[k].world_from_body.translation()).norm(), 0.01);
  }
  lock.unlock();
  EXPECT_THROW(ApplyGravityRefinement(lock, map(), *kf(kNum - 2), *problem, result), Error);
}

}  // namespace
}  // namespace pkslam
