// The points a new stereo keyframe brings (tracking/keyframe_points.h), on a synthetic frame.
#include "tracking/keyframe_points.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <utility>
#include <vector>

#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/matching_test_utils.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

SE3d CorrectedPose(double x, double y, double z) {
  return SE3d(SO3d::Exp(Eigen::Vector3d(0.01, -0.02, 0.03)), Eigen::Vector3d(x, y, z));
}

class KeyFramePointsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    rig_ = testing::MakeStereoRig();
    const SE3d pose = testing::MakeForwardPath(1, 0.1, 2)[0];
    frame_ = testing::MakeFrame(testing::MakeScene(600, 4, 4.0, 2.5, 1.5, 10.0), rig_, pose, 1, 0,
                                {}, &point_of_keypoint_);
    frame_.SetPose(pose);
  }
  KeyFramePtr MakeKeyFrame(const MapWriteLock& lock) {
    Map* map = atlas_.current_map();
    auto kf = std::make_shared<KeyFrame>(atlas_.NextKeyFrameId(), frame_, map);
    map->AddKeyFrame(lock, kf);
    return kf;
  }
  // Keypoint indices with a depth reading, nearest first.
  std::vector<int> ByDepth() const {
    std::vector<std::pair<float, int>> d;
    for (int i = 0; i < frame_.size(); ++i) {
      if (frame_.depth()[i] > 0) d.emplace_back(frame_.depth()[i], i);
    }
    std::sort(d.begin(), d.end());
    std::vector<int> order;
    for (const auto& [z, i] : d) order.push_back(i);
    return order;
  }

  Atlas atlas_;
  std::shared_ptr<CameraRig> rig_;
  Frame frame_;
  std::vector<int> point_of_keypoint_;
};

TEST_F(KeyFramePointsTest, AllCloseKeypointsBecomeObservedPointsAtTheirStereoPosition) {
  const std::vector<int> order = ByDepth();
  int close = 0;
  for (int i : order) close += frame_.depth()[i] <= rig_->th_depth ? 1 : 0;
  ASSERT_GT(close, 20);
  ASSERT_LT(close, static_cast<int>(order.size())) << "the scene needs far points too";
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  KeyFramePtr kf = MakeKeyFrame(lock);
  const ClosePointRule rule{rig_->th_depth, 5};
  const int created = AddClosePoints(lock, &atlas_, kf.get(), rule, &frame_);
  // The close ones and the first far one, where the walk stops.
  EXPECT_EQ(created, close + 1);
  EXPECT_EQ(atlas_.current_map()->NumMapPoints(), created);
  for (int n = 0; n < created; ++n) {
    const int i = order[n];
    const MapPointPtr& mp = frame_.map_points[i];
    ASSERT_NE(mp, nullptr) << i;
    EXPECT_EQ(kf->map_points()[i], mp);
    EXPECT_EQ(mp->observations().count(kf->id()), 1u);
    EXPECT_LT((mp->position() - *frame_.UnprojectStereo(i)).norm(), 1e-12);
  }
  for (std::size_t n = created; n < order.size(); ++n)
    EXPECT_EQ(frame_.map_points[order[n]], nullptr);
}

TEST_F(KeyFramePointsTest, AtLeastTheNearestMinCloseEvenWhenNoneIsClose) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  KeyFramePtr kf = MakeKeyFrame(lock);
  const ClosePointRule rule{0.01, 10};  // nothing is closer than 1 cm
  EXPECT_EQ(AddClosePoints(lock, &atlas_, kf.get(), rule, &frame_), 11);
}

TEST_F(KeyFramePointsTest, MatchedPointsStayAndTemporaryOnesAreReplaced) {
  const std::vector<int> order = ByDepth();
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  KeyFramePtr older = MakeKeyFrame(lock);
  const Eigen::Vector3d somewhere(0, 0, 5);
  auto matched = std::make_shared<MapPoint>(atlas_.NextMapPointId(), somewhere, older.get(),
                                            atlas_.current_map());
  matched->AddObservation(lock, older.get(), order[0]);
  frame_.map_points[order[0]] = matched;
  const MapPointPtr temporary = MapPoint::Temporary(somewhere, frame_.descriptors()[order[1]]);
  frame_.map_points[order[1]] = temporary;
  KeyFramePtr kf = MakeKeyFrame(lock);
  const ClosePointRule rule{0.01, 3};  // the nearest 4
  EXPECT_EQ(AddClosePoints(lock, &atlas_, kf.get(), rule, &frame_), 3);
  EXPECT_EQ(frame_.map_points[order[0]], matched);
  EXPECT_NE(frame_.map_points[order[1]], temporary);
  EXPECT_EQ(frame_.map_points[order[1]]->observations().count(kf->id()), 1u);
}

TEST_F(KeyFramePointsTest, RefusesToChangeTheMapWithoutTheWriteLock) {
  KeyFramePtr kf;
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    kf = MakeKeyFrame(lock);
  }
  auto unlocked = MapEditor(&atlas_).WriteLater(MapEdit::kFixture);
  EXPECT_THROW(AddClosePoints(unlocked, &atlas_, kf.get(), ClosePointRule{}, &frame_), Error);
  EXPECT_EQ(atlas_.current_map()->NumMapPoints(), 0);
}

TEST_F(KeyFramePointsTest, ANewKeyframeJoinsTheMapTheChainAndBringsItsClosePoints) {
  const testing::SyntheticScene scene = testing::MakeScene(600, 4, 4.0, 2.5, 1.5, 10.0);
  const Vocabulary vocabulary = testing::TrainSceneVocabulary(scene);
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  KeyFramePtr previous = MakeKeyFrame(lock);
  std::vector<std::pair<KeyFrame*, KeyFrame*>> attached;
  const SE3d corrected = CorrectedPose(0.01, 0.02, 0.03);
  const AttachKeyFrame attach = [&](const MapWriteLock& held, KeyFrame* kf, KeyFrame* prev,
                                    const Frame&) {
    attached.emplace_back(kf, prev);
    kf->SetPose(held, corrected);  // as the inertial attach does after a world change
  };
  Frame monocular = frame_;
  const KeyFramePtr plain =
      CreateKeyFrame(lock, &atlas_, vocabulary, attach, previous.get(), std::nullopt, &monocular);
  ASSERT_NE(plain, nullptr);
  EXPECT_EQ(atlas_.current_map()->NumKeyFrames(), 2);
  EXPECT_FALSE(plain->bow().empty()) << "the BoW was computed";
  ASSERT_EQ(attached.size(), 1u);
  EXPECT_EQ(attached[0], std::make_pair(plain.get(), previous.get()));
  EXPECT_TRUE(plain->camera_from_world().Log().isApprox(corrected.Log(), 1e-12));
  EXPECT_EQ(atlas_.current_map()->NumMapPoints(), 0) << "no close points asked for";

  const KeyFramePtr stereo = CreateKeyFrame(lock, &atlas_, vocabulary, attach, plain.get(),
                                            ClosePointRule{rig_->th_depth, 5}, &frame_);
  EXPECT_EQ(attached.back().second, plain.get());
  EXPECT_GT(atlas_.current_map()->NumMapPoints(), 20);
  EXPECT_EQ(static_cast<int>(stereo->GoodMapPoints().size()), atlas_.current_map()->NumMapPoints());
  lock.unlock();
  EXPECT_THROW(CreateKeyFrame(lock, &atlas_, vocabulary, attach, nullptr, std::nullopt, &frame_),
               Error);
}

}  // namespace
}  // namespace pkslam
