// How tracking starts a map (tracking/map_initializer.h), on synthetic stereo and monocular
// frames of one scene.
#include "tracking/map_initializer.h"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/matching_test_utils.h"
#include "map_model/testing/synthetic_map.h"
#include "tracking/tracking_options.h"

namespace pkslam {
namespace {

// The callback the tracker passes: records what it was asked to join.
struct AttachLog {
  std::vector<std::pair<KeyFrame*, KeyFrame*>> calls;  // (keyframe, previous)
  AttachKeyFrame Function() {
    return [this](const MapWriteLock& lock, KeyFrame* kf, KeyFrame* previous, const Frame&) {
      EXPECT_TRUE(lock.owns_lock());
      calls.emplace_back(kf, previous);
    };
  }
};

class MapInitializerTest : public ::testing::Test {
 protected:
  MapInitializerTest()
      : scene_(testing::MakeScene(1500, 11, 3.0, 2.0, 3.0, 8.0)),
        vocabulary_(testing::TrainSceneVocabulary(scene_)) {}

  Frame StereoFrame(const SE3d& camera_from_world) {
    std::vector<int> point_of_keypoint;
    return testing::MakeFrame(scene_, testing::MakeStereoRig(), camera_from_world, 1, 0, {},
                              &point_of_keypoint);
  }
  Frame MonocularFrame(const SE3d& camera_from_world, FrameId id, std::uint64_t seed,
                       std::vector<int>* point_of_keypoint) {
    testing::FrameOptions options;
    options.stereo = false;
    options.seed = seed;
    return testing::MakeFrame(scene_, testing::MakeStereoRig(Sensor::kMonocular), camera_from_world,
                              id, id * 50'000'000, options, point_of_keypoint);
  }

  testing::SyntheticScene scene_;
  Vocabulary vocabulary_;
  Atlas atlas_;
  AttachLog attach_;
};

TEST_F(MapInitializerTest, ADepthFrameStartsAMapWithAPointAtEachDepthReading) {
  const SE3d camera_from_world(SO3d::Exp(Eigen::Vector3d(0.02, -0.05, 0.01)),
                               Eigen::Vector3d(0.3, -0.1, 0.2));
  Frame frame = StereoFrame(camera_from_world);
  int with_depth = 0;
  for (int i = 0; i < frame.size(); ++i) with_depth += frame.HasDepth(i) ? 1 : 0;
  ASSERT_GT(with_depth, 100);
  TrackingOptions options;
  options.min_features_stereo_init = frame.size() - 1;
  options.min_depth_points_stereo_init = with_depth;
  EXPECT_TRUE(CanStartDepthMap(frame, options));
  options.min_depth_points_stereo_init = with_depth + 1;
  EXPECT_FALSE(CanStartDepthMap(frame, options)) << "one depth reading short";
  options.min_depth_points_stereo_init = 1;
  options.min_features_stereo_init = frame.size();
  EXPECT_FALSE(CanStartDepthMap(frame, options)) << "needs more keypoints than the threshold";

  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  const DepthMapStart start = StartDepthMap(lock, &atlas_, vocabulary_, attach_.Function(), &frame);
  ASSERT_NE(start.keyframe, nullptr);
  EXPECT_EQ(start.points, with_depth);
  EXPECT_EQ(atlas_.current_map()->NumKeyFrames(), 1);
  EXPECT_EQ(atlas_.current_map()->NumMapPoints(), with_depth);
  EXPECT_TRUE(start.keyframe->camera_from_world().Log().isZero(1e-12)) << "the origin";
  ASSERT_EQ(attach_.calls.size(), 1u);
  EXPECT_EQ(attach_.calls[0].second, nullptr) << "the first keyframe starts the chain";
  EXPECT_FALSE(start.keyframe->bow().empty());
  for (int i = 0; i < frame.size(); ++i) {
    const MapPointPtr& mp = frame.map_points[i];
    ASSERT_EQ(mp != nullptr, frame.HasDepth(i)) << "keypoint " << i;
    if (!mp) continue;
    EXPECT_EQ(mp->NumObservations(), 2) << "a stereo observation counts twice (ORB-SLAM)";
    EXPECT_EQ(start.keyframe->map_points()[i], mp);
    // The world is the frame's camera: the point sits at its stereo position in that camera.
    EXPECT_TRUE(mp->position().isApprox(*frame.UnprojectStereo(i), 1e-9));
  }
}

TEST_F(MapInitializerTest, StartDepthMapRefusesToRunWithoutTheLock) {
  Frame frame = StereoFrame(SE3d());
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  lock.unlock();
  EXPECT_THROW(StartDepthMap(lock, &atlas_, vocabulary_, attach_.Function(), &frame), Error);
  EXPECT_TRUE(attach_.calls.empty());
}

TEST_F(MapInitializerTest, TwoViewStartKeepsTheFirstFrameAndReconstructsTheSecond) {
  std::vector<int> keypoints1, keypoints2;
  const Frame first = MonocularFrame(SE3d(), 0, 3, &keypoints1);
  const SE3d camera2_from_camera1(SO3d::Exp(Eigen::Vector3d(0.0, 0.02, 0.0)),
                                  Eigen::Vector3d(-0.4, 0.05, 0.0));
  const Frame second = MonocularFrame(camera2_from_camera1, 1, 4, &keypoints2);
  TwoViewStart start;
  EXPECT_FALSE(start.Offer(first, 7).has_value());
  ASSERT_TRUE(start.started());
  const auto reconstruction = start.Offer(second, 7);
  ASSERT_TRUE(reconstruction.has_value());
  int matched = 0;
  for (std::size_t i = 0; i < start.matches().size(); ++i) {
    const int j = start.matches()[i];
    if (j < 0) continue;
    ++matched;
    EXPECT_TRUE(reconstruction->triangulated[i]) << "matches are cut to triangulated points";
    EXPECT_EQ(keypoints1[i], keypoints2[j]) << "a match pairs the same scene point";
  }
  EXPECT_EQ(matched, reconstruction->num_triangulated);
  EXPECT_GT(matched, 200);
  // Up to scale, the relative pose is the true one.
  const Eigen::Vector3d t = reconstruction->camera2_from_camera1.translation().normalized();
  EXPECT_GT(t.dot(camera2_from_camera1.translation().normalized()), 0.999);

  // A frame with too few keypoints drops the pair.
  const testing::SyntheticScene sparse = testing::MakeScene(90, 5);
  std::vector<int> unused;
  testing::FrameOptions mono;
  mono.stereo = false;
  const Frame poor = testing::MakeFrame(sparse, testing::MakeStereoRig(Sensor::kMonocular), SE3d(),
                                        2, 0, mono, &unused);
  EXPECT_FALSE(start.Offer(poor, 7).has_value());
  EXPECT_FALSE(start.started());
}

TEST_F(MapInitializerTest, ATwoViewMapIsRefinedAndScaledToAUnitMedianDepth) {
  std::vector<int> keypoints1, keypoints2;
  const SE3d camera2_from_camera1(SO3d::Exp(Eigen::Vector3d(0.0, 0.02, 0.0)),
                                  Eigen::Vector3d(-0.4, 0.05, 0.0));
  TwoViewStart start;
  start.Offer(MonocularFrame(SE3d(), 0, 3, &keypoints1), 7);
  Frame second = MonocularFrame(camera2_from_camera1, 1, 4, &keypoints2);
  const auto reconstruction = start.Offer(second, 7);
  ASSERT_TRUE(reconstruction.has_value());

  TwoViewKeyFrames map;
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    map = CreateTwoViewMap(lock, &atlas_, vocabulary_, attach_.Function(), *reconstruction,
                           start.matches(), &start.first(), &second);
  }
  ASSERT_EQ(attach_.calls.size(), 2u);
  EXPECT_EQ(attach_.calls[1].second, map.first.get()) << "the second follows the first";
  EXPECT_EQ(atlas_.current_map()->NumMapPoints(), reconstruction->num_triangulated);
  for (const MapPointPtr& mp : map.first->GoodMapPoints()) {
    EXPECT_EQ(mp->NumObservations(), 2);
    EXPECT_TRUE(mp->IsInKeyFrame(map.second.get()));
  }
  RefineTwoViewMap(&atlas_);
  auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
  const SE3d before = map.second->camera_from_world();
  const TwoViewScaling refused =
      NormaliseTwoViewScale(lock, map, reconstruction->num_triangulated + 1, &second);
  EXPECT_FALSE(refused.accepted) << "too few points";
  EXPECT_GT(refused.median_depth, 0);
  EXPECT_TRUE(map.second->camera_from_world().translation().isApprox(before.translation()));

  const TwoViewScaling scaling =
      NormaliseTwoViewScale(lock, map, TrackingOptions{}.min_two_view_map_points, &second);
  ASSERT_TRUE(scaling.accepted);
  EXPECT_NEAR(map.first->SceneDepthQuantile(0.5), 1.0, 1e-6);
  EXPECT_NEAR(map.second->camera_from_world().translation().norm(),
              before.translation().norm() / scaling.median_depth, 1e-9);
  EXPECT_TRUE(second.camera_from_world().translation().isApprox(
      map.second->camera_from_world().translation()));
  // The scaled map's baseline against its median depth is the true scene's, up to noise.
  const double true_ratio = camera2_from_camera1.translation().norm() / 5.5;  // depths 3..8 m
  EXPECT_NEAR(map.second->camera_from_world().translation().norm(), true_ratio, 0.3 * true_ratio);
}

}  // namespace
}  // namespace pkslam
