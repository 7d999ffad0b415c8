// The inertial chain's operations (map_model/inertial_chain.h) on a synthetic map: what each
// does to the links, the preintegrations and the prior, and what each refuses.
#include "map_model/inertial_chain.h"

#include <gtest/gtest.h>

#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

PreintegratedImu Interval(double dt) {
  PreintegratedImu pim;
  pim.dt = dt;
  pim.steps.push_back({Eigen::Vector3d(0, 0, 9.81), Eigen::Vector3d::Zero(), dt});
  return pim;
}

class InertialChainTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = testing::MakeStereoRig(Sensor::kStereoInertial);
    map_ = testing::MakeMap(&atlas_, testing::MakeScene(200, 3), rig_,
                            testing::MakeForwardPath(6, 0.15, 2), {});
  }
  KeyFrame* kf(int k) { return map_.keyframes[k].get(); }
  const InertialChain& chain() { return kf(0)->map()->inertial_chain(); }
  // Keyframes 0..n-1 appended in order, each interval `dt` long.
  void Link(const MapWriteLock& lock, int n, double dt = 0.05) {
    for (int k = 1; k < n; ++k) chain().Append(lock, kf(k - 1), kf(k), Interval(dt));
  }

  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticMap map_;
};

TEST_F(InertialChainTest, AppendLinksBothWaysAndKeepsTheInterval) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  Link(lock, 3);
  EXPECT_EQ(kf(0)->imu().previous(), nullptr);
  EXPECT_EQ(kf(0)->imu().next(), kf(1));
  EXPECT_EQ(kf(1)->imu().previous(), kf(0));
  EXPECT_EQ(kf(1)->imu().next(), kf(2));
  EXPECT_EQ(kf(2)->imu().next(), nullptr);
  ASSERT_TRUE(kf(2)->imu().from_previous.has_value());
  EXPECT_EQ(kf(2)->imu().from_previous->dt, 0.05);
  EXPECT_EQ(chain().Check(), std::nullopt);
  EXPECT_EQ(InertialChain::EndingAt(kf(2), 0), (std::vector<KeyFrame*>{kf(0), kf(1), kf(2)}));
  EXPECT_EQ(InertialChain::EndingAt(kf(2), 2), (std::vector<KeyFrame*>{kf(1), kf(2)}));
}

TEST_F(InertialChainTest, AnIntervalMissingAtAnImuGapLinksButEndsTheChainForEstimators) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  Link(lock, 2);
  chain().Append(lock, kf(1), kf(2), std::nullopt);
  EXPECT_EQ(kf(2)->imu().previous(), kf(1));
  EXPECT_EQ(InertialChain::EndingAt(kf(2), 0), (std::vector<KeyFrame*>{kf(2)}));
}

TEST_F(InertialChainTest, SpliceOutMergesTheIntervalAndDropsThePrior) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  Link(lock, 4);
  kf(2)->mutable_imu(lock).prior = InertialStatePrior();
  kf(2)->SetBad(lock);
  chain().SpliceOut(lock, kf(2));
  EXPECT_EQ(kf(1)->imu().next(), kf(3));
  EXPECT_EQ(kf(3)->imu().previous(), kf(1));
  EXPECT_NEAR(kf(3)->imu().from_previous->dt, 0.10, 1e-12);  // both intervals
  EXPECT_EQ(kf(2)->imu().previous(), nullptr);
  EXPECT_EQ(kf(2)->imu().next(), nullptr);
  EXPECT_FALSE(kf(2)->imu().from_previous.has_value());
  EXPECT_FALSE(kf(2)->imu().prior.has_value());
  EXPECT_EQ(chain().Check(), std::nullopt);
  EXPECT_EQ(InertialChain::EndingAt(kf(3), 0), (std::vector<KeyFrame*>{kf(0), kf(1), kf(3)}));
}

TEST_F(InertialChainTest, SpliceOutWithoutBothIntervalsCutsTheChain) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  Link(lock, 2);
  chain().Append(lock, kf(1), kf(2), std::nullopt);
  chain().Append(lock, kf(2), kf(3), Interval(0.05));
  chain().SpliceOut(lock, kf(2));  // no interval 1 -> 2 to merge
  EXPECT_EQ(kf(1)->imu().next(), nullptr);
  EXPECT_EQ(kf(3)->imu().previous(), nullptr);
  EXPECT_FALSE(kf(3)->imu().from_previous.has_value());
  EXPECT_EQ(chain().Check(), std::nullopt);
}

TEST_F(InertialChainTest, RefusesKeyframesOfAnotherMapAndChangesWithoutTheWriteLock) {
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    Map* other = atlas_.CreateNewMap(lock);
    kf(5)->set_map(other);  // as if merged away
    EXPECT_THROW(chain().Append(lock, kf(4), kf(5), Interval(0.05)), Error);
    EXPECT_EQ(kf(4)->imu().next(), nullptr);
    kf(5)->set_map(kf(0)->map());
  }
  auto unlocked = MapEditor(&atlas_).WriteLater(MapEdit::kFixture);
  EXPECT_THROW(chain().Append(unlocked, kf(0), kf(1), Interval(0.05)), Error);
  EXPECT_EQ(kf(0)->imu().next(), nullptr);
}

}  // namespace
}  // namespace pkslam
