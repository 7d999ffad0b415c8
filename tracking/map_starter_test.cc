// The Tracker's map initialiser (tracking/map_starter.h) on synthetic stereo and monocular
// frames of one scene.
#include "tracking/map_starter.h"

#include <gtest/gtest.h>

#include <vector>

#include "map_model/atlas.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/matching/matching_test_utils.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

class MapStarterTest : public ::testing::Test {
 protected:
  MapStarterTest()
      : scene_(testing::MakeScene(1500, 11, 3.0, 2.0, 3.0, 8.0)),
        vocabulary_(testing::TrainSceneVocabulary(scene_)) {}

  Frame MakeSceneFrame(const SE3d& camera_from_world, FrameId id, bool stereo) {
    testing::FrameOptions options;
    options.stereo = stereo;
    options.seed = static_cast<std::uint64_t>(id) + 3;
    std::vector<int> point_of_keypoint;
    const Sensor sensor = stereo ? Sensor::kStereo : Sensor::kMonocular;
    return testing::MakeFrame(scene_, testing::MakeStereoRig(sensor), camera_from_world, id,
                              id * 50'000'000, options, &point_of_keypoint);
  }
  AttachKeyFrame CountAttach() {
    return [this](const MapWriteLock& lock, KeyFrame*, KeyFrame*, const Frame&) {
      EXPECT_TRUE(lock.owns_lock());
      ++attached_;
    };
  }

  testing::SyntheticScene scene_;
  Vocabulary vocabulary_;
  Atlas atlas_;
  LocalMap local_map_{20};
  int attached_ = 0;
};

TEST_F(MapStarterTest, OneDepthFrameStartsAMapAndSeedsTheLocalMap) {
  TrackingOptions options;
  Frame frame = MakeSceneFrame(SE3d(), 1, /*stereo=*/true);
  int with_depth = 0;
  for (int i = 0; i < frame.size(); ++i) with_depth += frame.HasDepth(i) ? 1 : 0;

  options.min_depth_points_stereo_init = with_depth + 1;
  MapStarter refusing(&atlas_, &vocabulary_, /*monocular=*/false, options);
  EXPECT_FALSE(refusing.Offer(&frame, CountAttach(), &local_map_).started());
  EXPECT_EQ(atlas_.current_map()->NumKeyFrames(), 0) << "too few depth readings: no map";

  options.min_depth_points_stereo_init = with_depth;
  MapStarter starter(&atlas_, &vocabulary_, /*monocular=*/false, options);
  const StartedMap started = starter.Offer(&frame, CountAttach(), &local_map_);
  ASSERT_TRUE(started.started());
  ASSERT_EQ(started.keyframes.size(), 1u);
  EXPECT_EQ(started.TrackedPoints(), with_depth);
  EXPECT_FALSE(started.first_of_pair.has_value());
  EXPECT_FALSE(started.refused);
  EXPECT_EQ(attached_, 1);
  EXPECT_EQ(atlas_.current_map()->NumKeyFrames(), 1);
  ASSERT_EQ(local_map_.keyframes().size(), 1u);
  EXPECT_EQ(local_map_.keyframes()[0], started.newest().get());
  EXPECT_EQ(static_cast<int>(local_map_.points().size()), with_depth);
  EXPECT_EQ(frame.map_points.size(), static_cast<std::size_t>(frame.size()));
  EXPECT_EQ(starter.pair_first(), nullptr) << "stereo never pairs frames";
}

TEST_F(MapStarterTest, TwoMonocularViewsStartAMapWithThePairsFirstFrame) {
  MapStarter starter(&atlas_, &vocabulary_, /*monocular=*/true, TrackingOptions{});
  Frame first = MakeSceneFrame(SE3d(), 0, /*stereo=*/false);
  EXPECT_FALSE(starter.Offer(&first, CountAttach(), &local_map_).started());
  ASSERT_NE(starter.pair_first(), nullptr);
  EXPECT_EQ(starter.pair_first()->id(), 0);

  const SE3d camera2_from_camera1(SO3d::Exp(Eigen::Vector3d(0.0, 0.02, 0.0)),
                                  Eigen::Vector3d(-0.4, 0.05, 0.0));
  Frame second = MakeSceneFrame(camera2_from_camera1, 1, /*stereo=*/false);
  const StartedMap started = starter.Offer(&second, CountAttach(), &local_map_);
  ASSERT_TRUE(started.started());
  ASSERT_EQ(started.keyframes.size(), 2u);
  EXPECT_EQ(started.keyframes[0]->frame_id(), 0);
  EXPECT_EQ(started.newest()->frame_id(), 1);
  ASSERT_TRUE(started.first_of_pair.has_value());
  EXPECT_EQ(started.first_of_pair->id(), 0);
  EXPECT_EQ(starter.pair_first(), nullptr) << "the pair is used up";
  EXPECT_EQ(attached_, 2);
  EXPECT_GE(started.TrackedPoints(), TrackingOptions{}.min_two_view_map_points);
  EXPECT_EQ(started.TrackedPoints(), atlas_.current_map()->NumMapPoints());
  EXPECT_EQ(local_map_.keyframes().size(), 2u);
  // Scaled to a unit median depth, and the frame sits where its keyframe is.
  EXPECT_NEAR(started.keyframes[0]->SceneDepthQuantile(0.5), 1.0, 1e-6);
  EXPECT_TRUE(second.camera_from_world().translation().isApprox(
      started.newest()->camera_from_world().translation()));

  starter.Reset();
  EXPECT_EQ(starter.pair_first(), nullptr);
}

// A pair that reconstructs but leaves the second keyframe fewer points than the options ask is
// refused: no keyframes are handed back and the local map is not seeded; the two keyframes
// stay in the map for the caller to reset it (the Tracker does, as ORB-SLAM3).
TEST_F(MapStarterTest, ATwoViewMapWithTooFewPointsIsRefusedForTheCallerToReset) {
  TrackingOptions options;
  options.min_two_view_map_points = 100'000;
  MapStarter starter(&atlas_, &vocabulary_, /*monocular=*/true, options);
  Frame first = MakeSceneFrame(SE3d(), 0, /*stereo=*/false);
  EXPECT_FALSE(starter.Offer(&first, CountAttach(), &local_map_).refused);
  const SE3d camera2_from_camera1(SO3d::Exp(Eigen::Vector3d(0.0, 0.02, 0.0)),
                                  Eigen::Vector3d(-0.4, 0.05, 0.0));
  Frame second = MakeSceneFrame(camera2_from_camera1, 1, /*stereo=*/false);
  const StartedMap refused = starter.Offer(&second, CountAttach(), &local_map_);
  EXPECT_TRUE(refused.refused);
  EXPECT_FALSE(refused.started());
  EXPECT_FALSE(refused.first_of_pair.has_value());
  EXPECT_TRUE(local_map_.keyframes().empty());
  EXPECT_EQ(attached_, 2) << "the map was built before it was judged";
  auto lock = MapReader(atlas_).Lock();
  EXPECT_EQ(atlas_.current_map()->NumKeyFrames(), 2);
  EXPECT_GE(atlas_.current_map()->NumMapPoints(), TrackingOptions{}.min_two_view_map_points)
      << "the same pair is accepted with the default bound";
}

}  // namespace
}  // namespace pkslam
