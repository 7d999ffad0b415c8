#include "mapping/inertial_init_chain.h"

#include <gtest/gtest.h>

#include <mutex>
#include <vector>

#include "imu/imu_test_utils.h"
#include "imu/preintegration.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/testing/imu_chain.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

using testing::HelixMotion;
using testing::kTestGravity;

// Keyframes every 50 ms (MakeMap's spacing) at their true poses on the helix (camera = body),
// linked by exact IMU preintegrations at `bias`; no inertial states yet.
class InertialInitChainTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = testing::MakeStereoRig(Sensor::kStereoInertial);
    rig_->imu = ImuNoise();
    std::vector<SE3d> camera_from_world;
    for (int k = 0; k < kNum; ++k) {
      truth_.push_back(motion_.State(0.05 * k));
      camera_from_world.push_back(truth_.back().world_from_body.Inverse());
    }
    map_ = testing::MakeMap(&atlas_, testing::MakeScene(300, 5), rig_, camera_from_world,
                            testing::FrameOptions());
    const auto samples =
        SampleImu(motion_, 0, (kNum - 1) * 50'000'000LL, 5'000'000, bias_, *rig_->imu, nullptr);
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    testing::LinkWithImu(lock, map_.keyframes, samples, bias_, *rig_->imu);
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

TEST_F(InertialInitChainTest, ChainRunsThroughTheKeyFramesLinkedAfter) {
  auto lock = MapReader(atlas_).Lock();
  const std::vector<KeyFrame*> chain = InertialChainThrough(kf(3));
  ASSERT_EQ(chain.size(), static_cast<std::size_t>(kNum));
  for (int k = 0; k < kNum; ++k) EXPECT_EQ(chain[k], kf(k));
}

TEST_F(InertialInitChainTest, ChainStopsWhereTheLinkBreaks) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  kf(6)->imu.from_previous.reset();  // an IMU gap before keyframe 6
  const std::vector<KeyFrame*> chain = InertialChainThrough(kf(3));
  ASSERT_EQ(chain.size(), 6u);
  EXPECT_EQ(chain.front(), kf(0));
  EXPECT_EQ(chain.back(), kf(5));
  // From the other side of the gap the chain starts at 6.
  const std::vector<KeyFrame*> after = InertialChainThrough(kf(7));
  ASSERT_EQ(after.size(), 2u);
  EXPECT_EQ(after.front(), kf(6));
}

TEST_F(InertialInitChainTest, PropagatedVelocitiesFollowTheImu) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  // Metric = 2 * map units: the chain's velocities are in map units, so are the predictions.
  const double scale = 2.0;
  for (int k = 0; k <= 3; ++k) {
    kf(k)->imu.state.velocity_world = truth_[k].velocity_world / scale;
    kf(k)->imu.state.valid = true;
  }
  // Keyframe 6 already has an estimate (tracking's): the propagation stops before it.
  kf(6)->imu.state.velocity_world = Eigen::Vector3d(9, 9, 9);
  kf(6)->imu.state.valid = true;
  EXPECT_EQ(PropagateVelocities(kf(3), bias_, kTestGravity, scale), 2);
  for (int k = 4; k <= 5; ++k) {
    ASSERT_TRUE(kf(k)->imu.state.valid);
    EXPECT_LT((scale * kf(k)->imu.state.velocity_world - truth_[k].velocity_world).norm(), 0.01)
        << "keyframe " << k;
  }
  EXPECT_EQ(kf(6)->imu.state.velocity_world, Eigen::Vector3d(9, 9, 9));
  EXPECT_FALSE(kf(7)->imu.state.valid);
  // Nothing to do from a keyframe without a state.
  EXPECT_EQ(PropagateVelocities(kf(7), bias_, kTestGravity, scale), 0);
}

}  // namespace
}  // namespace pkslam
