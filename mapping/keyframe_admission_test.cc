// A keyframe from tracking enters the map (mapping/keyframe_admission.h), on a synthetic map.
#include "mapping/keyframe_admission.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>

#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

class KeyFrameAdmissionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = testing::MakeScene(300, 6);
    rig_ = testing::MakeStereoRig();
    const auto path = testing::MakeForwardPath(4, 0.1, 4);
    map_ = testing::MakeMap(&atlas_, scene_, rig_, {path[0], path[1], path[2]}, {});
    // Tracking's keyframe at the fourth pose: its keypoints matched to the map's points, and
    // one point of its own (a close stereo point tracking created for it).
    std::vector<int> point_of_keypoint;
    Frame frame = testing::MakeFrame(scene_, rig_, path[3], 10, 0, {}, &point_of_keypoint);
    frame.SetPose(path[3]);
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    Map* map = atlas_.current_map();
    for (int i = 0; i < frame.size() && own_index_ < 0; ++i) {
      if (frame.HasDepth(i)) own_index_ = i;
    }
    own_ = std::make_shared<MapPoint>(atlas_.NextMapPointId(), *frame.UnprojectStereo(own_index_),
                                      nullptr, map);
    for (int i = 0; i < frame.size(); ++i) {
      const MapPointPtr& mp = map_.point_of_scene_index[point_of_keypoint[i]];
      if (mp && i != own_index_) {
        frame.map_points[i] = mp;
        ++matched_;
      }
    }
    keyframe_ = std::make_shared<KeyFrame>(atlas_.NextKeyFrameId(), frame, map);
    map->AddKeyFrame(lock, keyframe_);
    own_->AddObservation(lock, keyframe_.get(), own_index_);
    keyframe_->AddMapPoint(lock, own_, own_index_);
    map->AddMapPoint(lock, own_);
  }

  Atlas atlas_;
  testing::SyntheticScene scene_;
  std::shared_ptr<CameraRig> rig_;
  testing::SyntheticMap map_;
  KeyFramePtr keyframe_;
  MapPointPtr own_;
  int own_index_ = -1;
  int matched_ = 0;
};

TEST_F(KeyFrameAdmissionTest, TheKeyframeObservesItsMatchesAndReturnsItsOwnPoints) {
  ASSERT_GT(matched_, 50);
  ASSERT_NE(own_, nullptr);
  EXPECT_TRUE(keyframe_->BestCovisibles(10).empty()) << "no links before admission";
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  const std::vector<MapPointPtr> created = AdmitKeyFrame(lock, &atlas_, keyframe_.get());
  ASSERT_EQ(created.size(), 1u);
  EXPECT_EQ(created[0], own_);
  int observing = 0;
  for (const MapPointPtr& mp : keyframe_->GoodMapPoints()) {
    EXPECT_TRUE(mp->IsInKeyFrame(keyframe_.get()));
    observing += mp != own_ ? 1 : 0;
  }
  EXPECT_EQ(observing, matched_);
  // Linked to the three keyframes it shares points with.
  const auto covisible = keyframe_->BestCovisibles(10);
  EXPECT_EQ(covisible.size(), 3u);
  EXPECT_NE(std::find(covisible.begin(), covisible.end(), map_.keyframes[0].get()),
            covisible.end());
}

TEST_F(KeyFrameAdmissionTest, ARetiredKeyframeIsLeftAloneAndTheLockIsRequired) {
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  lock.unlock();
  EXPECT_THROW(AdmitKeyFrame(lock, &atlas_, keyframe_.get()), Error);
  lock.lock();
  keyframe_->SetBad(lock);
  EXPECT_TRUE(AdmitKeyFrame(lock, &atlas_, keyframe_.get()).empty());
  EXPECT_FALSE(map_.point_of_scene_index[0] &&
               map_.point_of_scene_index[0]->IsInKeyFrame(keyframe_.get()));
}

}  // namespace
}  // namespace pkslam
