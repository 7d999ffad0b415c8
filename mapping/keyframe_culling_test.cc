// Keyframe culling (mapping/keyframe_culling.h) on synthetic maps: a keyframe among many that
// see the same points is redundant, one whose points few others see is not, and the culling
// never retires the origin.
#include "mapping/keyframe_culling.h"

#include <gtest/gtest.h>

#include <memory>
#include <mutex>
#include <shared_mutex>

#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

class KeyFrameCullingTest : public ::testing::Test {
 protected:
  // `n` keyframes `step` m apart along a forward path, all seeing one scene.
  void Build(int n, double step) {
    rig_ = testing::MakeStereoRig();
    map_ = testing::MakeMap(&atlas_, testing::MakeScene(400, 11), rig_,
                            testing::MakeForwardPath(n, step, 3), {});
  }
  KeyFrame* kf(int k) { return map_.keyframes[k].get(); }

  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticMap map_;
};

TEST_F(KeyFrameCullingTest, AKeyframeAmongManySeeingItsPointsIsRedundant) {
  Build(8, 0.02);  // 2 cm apart: every point seen by all 8 at about the same scale
  auto lock = MapReader(atlas_).Lock();
  KeyFrameRedundancy rule;
  EXPECT_TRUE(IsRedundant(*kf(4), rule));
  rule.observers = 7;  // there are only 7 others
  EXPECT_TRUE(IsRedundant(*kf(4), rule));
  rule.observers = 8;
  EXPECT_FALSE(IsRedundant(*kf(4), rule));
}

TEST_F(KeyFrameCullingTest, StereoCountsOnlyCloseEnoughPoints) {
  Build(8, 0.02);
  auto lock = MapReader(atlas_).Lock();
  KeyFrameRedundancy rule;
  rule.max_depth = 0.5;  // the scene is 3-8 m away: no point of its own
  EXPECT_FALSE(IsRedundant(*kf(4), rule));
  rule.max_depth = 100.0;
  EXPECT_TRUE(IsRedundant(*kf(4), rule));
}

TEST_F(KeyFrameCullingTest, CullingRetiresRedundantKeyframesButNeverTheOrigin) {
  Build(8, 0.02);
  const KeyFrame* origin = kf(0)->map()->origin();
  ASSERT_NE(origin, nullptr);
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  KeyFrameCullingInput input;
  const int culled = CullRedundantKeyFrames(lock, kf(7), input);
  EXPECT_GT(culled, 0);
  EXPECT_FALSE(origin->IsBad());
  EXPECT_FALSE(kf(7)->IsBad()) << "the newest keyframe is not its own candidate";
  int retired = 0;
  for (const auto& k : map_.keyframes) retired += k->IsBad() ? 1 : 0;
  EXPECT_EQ(retired, culled);
  EXPECT_EQ(static_cast<int>(kf(0)->map()->retired_keyframes().size()), culled);
}

TEST_F(KeyFrameCullingTest, KeyframesSeeingDifferentPointsStay) {
  Build(6, 1.5);  // 1.5 m apart along the view: few points seen by 3 others at its scale
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  KeyFrameCullingInput input;
  EXPECT_EQ(CullRedundantKeyFrames(lock, kf(5), input), 0);
  for (const auto& k : map_.keyframes) EXPECT_FALSE(k->IsBad());
}

}  // namespace
}  // namespace pkslam
