// Keyframe culling in inertial maps: the temporal chain's spacing rules and the splicing that
// merges the culled keyframe's preintegration into its successor's.
#include "mapping/inertial_culling.h"

#include <gtest/gtest.h>

#include <mutex>

#include "imu/imu_test_utils.h"
#include "imu/preintegration.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

constexpr int kNumKeyFrames = 30;
constexpr std::int64_t kCullingPeriodNs = 50'000'000;  // synthetic map keyframes, 20 Hz

class InertialCullingTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = testing::MakeStereoRig(Sensor::kStereoInertial);
    map_ = testing::MakeMap(&atlas_, testing::MakeScene(400, 5), rig_,
                            testing::MakeForwardPath(kNumKeyFrames, 0.15, 4), {});
    samples_ = testing::SampleImu(testing::HelixMotion(), 0, kCullingPeriodNs * kNumKeyFrames,
                                  5'000'000, bias_, noise_, nullptr);
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    for (int k = 0; k < kNumKeyFrames; ++k) {
      KeyFrame* kf = map_.keyframes[k].get();
      ASSERT_EQ(kf->t_ns(), k * kCullingPeriodNs);
      kf->mutable_imu(lock).state.bias = bias_;
      if (k == 0) continue;
      KeyFrame* previous = map_.keyframes[k - 1].get();
      map_.keyframes[0]->map()->inertial_chain().Append(lock, previous, kf,
                                                        Integrate(previous->t_ns(), kf->t_ns()));
    }
  }

  PreintegratedImu Integrate(std::int64_t t0_ns, std::int64_t t1_ns) const {
    PreintegratedImu pim = StartPreintegration(bias_, noise_);
    IntegrateSamples(samples_, t0_ns, t1_ns, &pim);
    return pim;
  }
  KeyFrame* kf(int k) { return map_.keyframes[k].get(); }
  void Retire(const MapWriteLock& lock, int k) {
    kf(k)->SetBad(lock);
    ASSERT_TRUE(kf(k)->IsBad());
    map_.keyframes[0]->map()->inertial_chain().SpliceOut(lock, kf(k));
  }

  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticMap map_;
  ImuBias bias_{Eigen::Vector3d(0.002, -0.001, 0.003), Eigen::Vector3d(0.05, 0.02, -0.04)};
  ImuNoise noise_;
  std::vector<ImuMeasurement> samples_;
};

TEST_F(InertialCullingTest, SplicingMergesThePreintegrationIntoTheSuccessor) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  kf(4)->mutable_imu(lock).state.bias =
      ImuBias(Eigen::Vector3d(0.001, 0, 0), Eigen::Vector3d(0.01, 0, 0));
  Retire(lock, 5);
  EXPECT_EQ(kf(6)->imu().previous(), kf(4));
  EXPECT_EQ(kf(4)->imu().next(), kf(6));
  EXPECT_EQ(kf(5)->imu().previous(), nullptr);
  EXPECT_EQ(kf(5)->imu().next(), nullptr);
  EXPECT_FALSE(kf(5)->imu().from_previous.has_value());
  // The same as integrating 4 -> 6 directly, linearised at keyframe 4's bias.
  PreintegratedImu direct = StartPreintegration(kf(4)->imu().state.bias, noise_);
  IntegrateSamples(samples_, kf(4)->t_ns(), kf(6)->t_ns(), &direct);
  const PreintegratedImu& merged = *kf(6)->imu().from_previous;
  EXPECT_NEAR(merged.dt, 0.1, 1e-12);
  EXPECT_LT((merged.bias.accel - kf(4)->imu().state.bias.accel).norm(), 1e-15);
  EXPECT_LT((merged.delta_R.Log() - direct.delta_R.Log()).norm(), 1e-9);
  EXPECT_LT((merged.delta_v - direct.delta_v).norm(), 1e-9);
  EXPECT_LT((merged.delta_p - direct.delta_p).norm(), 1e-9);
  EXPECT_LT((merged.covariance - direct.covariance).norm(), 1e-12);
}

TEST_F(InertialCullingTest, ContextFindsTheStartOfTheNewestWindow) {
  auto lock = MapReader(atlas_).Lock();
  InertialCullingOptions options;
  options.window = 21;
  const InertialCullingContext c = MakeInertialCullingContext(*kf(29), options);
  EXPECT_EQ(c.current_id, kf(29)->id());
  EXPECT_EQ(c.window_start_id, kf(9)->id());
  EXPECT_EQ(c.map_keyframes, kNumKeyFrames);
}

TEST_F(InertialCullingTest, TimeSpacingDecidesWhichRedundantKeyFramesMayGo) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  InertialCullingOptions options;
  InertialCullingContext c;
  c.current_id = kf(29)->id();
  c.window_start_id = kf(20)->id();
  c.map_keyframes = kNumKeyFrames;
  c.imu_initialized = true;
  c.refined = true;
  // Neighbours 0.1 s apart: allowed anywhere but for the two newest.
  EXPECT_TRUE(InertialCullingAllowed(*kf(25), c, options));
  EXPECT_FALSE(InertialCullingAllowed(*kf(28), c, options));
  EXPECT_FALSE(InertialCullingAllowed(*kf(29), c, options));
  // A small map keeps everything.
  InertialCullingContext small = c;
  small.map_keyframes = options.window;
  EXPECT_FALSE(InertialCullingAllowed(*kf(25), small, options));
  // Retire 1..11: keyframe 12 then sits between 0 and 13, 0.65 s apart.
  for (int k = 1; k <= 11; ++k) Retire(lock, k);
  ASSERT_EQ(kf(12)->imu().previous(), kf(0));
  EXPECT_TRUE(InertialCullingAllowed(*kf(12), c, options));  // older than the window
  InertialCullingContext recent = c;
  recent.window_start_id = kf(10)->id();
  EXPECT_FALSE(InertialCullingAllowed(*kf(12), recent, options));  // inside it: > 0.5 s
  InertialCullingContext uninitialised = c;
  uninitialised.imu_initialized = false;
  uninitialised.refined = false;
  EXPECT_FALSE(InertialCullingAllowed(*kf(12), uninitialised, options));  // it moved
  options.still_distance = 100.0;  // everything counts as still
  EXPECT_TRUE(InertialCullingAllowed(*kf(12), uninitialised, options));
  // Never across more than max_gap_old_s.
  options.max_gap_old_s = 0.6;
  EXPECT_FALSE(InertialCullingAllowed(*kf(12), c, options));
  options.enabled = false;
  EXPECT_FALSE(InertialCullingAllowed(*kf(25), c, options));
}

TEST_F(InertialCullingTest, RepairSplicesKeyFramesRetiredWithoutSplicing) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  kf(15)->SetBad(lock);
  kf(16)->SetBad(lock);
  ASSERT_EQ(kf(17)->imu().previous(), kf(16));
  EXPECT_EQ(RepairInertialChain(lock, kf(29), 42), 2);
  EXPECT_EQ(kf(17)->imu().previous(), kf(14));
  EXPECT_EQ(kf(14)->imu().next(), kf(17));
  EXPECT_NEAR(kf(17)->imu().from_previous->dt, 0.15, 1e-12);
  EXPECT_EQ(RepairInertialChain(lock, kf(29), 42), 0);
}

}  // namespace
}  // namespace pkslam
