// Marginalisation prior of the local inertial BA, map side (the value math is tested in
// estimators/inertial/marginalization_test.cc): the validity stamps, and Collect / Apply on a
// synthetic inertial map (the anchor is free with a valid prior, fixed with a stale one, and
// the solve's marginal lands on the next keyframe).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <mutex>
#include <random>

#include "core/util/error.h"
#include "imu/imu_factors.h"
#include "imu/imu_manifolds.h"
#include "imu/imu_test_utils.h"
#include "imu/preintegration.h"
#include "map_model/estimation/inertial_bundle_collect.h"
#include "map_model/estimation/inertial_prior_stamp.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/testing/imu_chain.h"
#include "map_model/testing/synthetic_map.h"
#include "mapping/inertial_culling.h"

namespace pkslam {
namespace {

constexpr int kChainKeyFrames = 16;
constexpr std::int64_t kChainPeriodNs = 50'000'000;

// A synthetic stereo-inertial map whose keyframes form a temporal chain with valid states.
class MarginalizationMapTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = testing::MakeStereoRig(Sensor::kStereoInertial);
    map_ = testing::MakeMap(&atlas_, testing::MakeScene(400, 5), rig_,
                            testing::MakeForwardPath(kChainKeyFrames, 0.15, 4), {});
    const auto samples =
        testing::SampleImu(testing::HelixMotion(), 0, kChainPeriodNs * kChainKeyFrames, 5'000'000,
                           bias_, noise_, nullptr);
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    for (int k = 0; k < kChainKeyFrames; ++k) {
      KeyFrame* kf = map_.keyframes[k].get();
      kf->mutable_imu(lock).state.bias = bias_;
      kf->mutable_imu(lock).state.valid = true;
    }
    testing::LinkWithImu(lock, map_.keyframes, samples, bias_, noise_);
    map()->mutable_imu_status(lock).imu_initialized = true;
    options_.window = 5;
  }
  KeyFrame* kf(int k) { return map_.keyframes[k].get(); }
  Map* map() { return kf(0)->map(); }
  KeyFrame* newest() { return kf(kChainKeyFrames - 1); }
  KeyFrame* anchor() { return kf(kChainKeyFrames - 1 - options_.window); }
  // A prior at the anchor's current state, stamped with the map.
  void GiveAnchorPrior(const MapWriteLock& lock, double information) {
    InertialStatePrior prior;
    prior.mean.world_from_body =
        anchor()->world_from_camera() * anchor()->rig().body_from_camera.Inverse();
    prior.mean.velocity_world = anchor()->imu().state.velocity_world;
    prior.bias_mean = anchor()->imu().state.bias;
    prior.information = information * Eigen::Matrix<double, 15, 15>::Identity();
    StampPrior(*map(), &prior);
    anchor()->mutable_imu(lock).prior = prior;
  }

  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticMap map_;
  ImuBias bias_{Eigen::Vector3d(0.002, -0.001, 0.003), Eigen::Vector3d(0.05, 0.02, -0.04)};
  ImuNoise noise_;
  InertialBundleOptions options_;
};

TEST_F(MarginalizationMapTest, ValidPriorFreesTheAnchorStalePriorIsIgnored) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  {
    const InertialBundleProblem p = CollectLocalInertialBundle(newest(), options_);
    ASSERT_FALSE(p.empty());
    EXPECT_EQ(p.visual.keyframes[0].keyframe_id, anchor()->id());
    EXPECT_TRUE(p.visual.keyframes[0].fixed);  // no prior yet: fixed (ORB-SLAM3)
    EXPECT_FALSE(p.anchor_prior.has_value());
    EXPECT_EQ(p.marginalize_from, 0);
    EXPECT_EQ(p.marginalize_to, 1);
  }
  GiveAnchorPrior(lock, 1e4);
  {
    const InertialBundleProblem p = CollectLocalInertialBundle(newest(), options_);
    EXPECT_FALSE(p.visual.keyframes[0].fixed);
    ASSERT_TRUE(p.anchor_prior.has_value());
    EXPECT_EQ(p.inertial[0], 1);
  }
  InertialBundleOptions off = options_;
  off.marginalization_prior = false;
  {
    const InertialBundleProblem p = CollectLocalInertialBundle(newest(), off);
    EXPECT_TRUE(p.visual.keyframes[0].fixed);
    EXPECT_FALSE(p.anchor_prior.has_value());
    EXPECT_EQ(p.marginalize_from, -1);
  }
  // A loop correction / merge / global or full inertial BA moved the map: stale.
  map()->IncreaseChangeIndex(lock);
  EXPECT_FALSE(PriorIsValid(*anchor()->imu().prior, *map()));
  {
    const InertialBundleProblem p = CollectLocalInertialBundle(newest(), options_);
    EXPECT_TRUE(p.visual.keyframes[0].fixed);
    EXPECT_FALSE(p.anchor_prior.has_value());
  }
  // An IMU initialisation / refinement rotated the map: stale too.
  GiveAnchorPrior(lock, 1e4);
  EXPECT_TRUE(PriorIsValid(*anchor()->imu().prior, *map()));
  map()->RecordWorldChange(lock, {WorldChange::Kind::kTransform, SO3d(), 1.0});
  EXPECT_FALSE(PriorIsValid(*anchor()->imu().prior, *map()));
  // Another map.
  GiveAnchorPrior(lock, 1e4);
  InertialStatePrior other = *anchor()->imu().prior;
  other.map_id = map()->id() + 1;
  EXPECT_FALSE(PriorIsValid(other, *map()));
}

TEST_F(MarginalizationMapTest, CulledKeyFrameDropsItsPrior) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  GiveAnchorPrior(lock, 1e4);
  KeyFrame* k = anchor();
  k->SetBad(lock);
  map()->inertial_chain().SpliceOut(lock, k);
  EXPECT_FALSE(k->imu().prior.has_value());
}

TEST_F(MarginalizationMapTest, SolveMarginalisesTheAnchorOntoTheNextKeyFrame) {
  InertialBundleProblem p;
  {
    auto lock = MapReader(atlas_).Lock();
    p = CollectLocalInertialBundle(newest(), options_);
  }
  const InertialBundleResult r = SolveInertialBundle(p, options_);
  ASSERT_TRUE(r.next_prior.has_value());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 15, 15>> es(r.next_prior->information);
  EXPECT_GE(es.eigenvalues().minCoeff(), -1e-9 * es.eigenvalues().maxCoeff());
  // The anchor's reprojections fix its pose, the edge carries that to the next pose.
  EXPECT_GT((r.next_prior->information.topLeftCorner<6, 6>().trace()), 1.0);
  KeyFrame* next = kf(kChainKeyFrames - options_.window);
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    ApplyInertialBundle(lock, map(), p, r);
    ASSERT_TRUE(next->imu().prior.has_value());
    EXPECT_TRUE(PriorIsValid(*next->imu().prior, *map()));
    EXPECT_EQ(next->imu().prior->bias_mean.gyro, r.next_prior->bias_mean.gyro);
    EXPECT_TRUE(next->imu().prior->mean.velocity_world.allFinite());
    // Applying a result collected before a map-wide change stores nothing.
    next->mutable_imu(lock).prior.reset();
    map()->IncreaseChangeIndex(lock);
    ApplyInertialBundle(lock, map(), p, r);
    EXPECT_FALSE(next->imu().prior.has_value());
  }
}

}  // namespace
}  // namespace pkslam
