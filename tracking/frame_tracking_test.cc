// Tracking a frame against the last frame or a keyframe (tracking/frame_tracking.h), on a
// synthetic stereo map with BoW.
#include "tracking/frame_tracking.h"

#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/matching_test_utils.h"

namespace pkslam {
namespace {

class FrameTrackingTest : public ::testing::Test {
 protected:
  // A frame of the scene at `camera_from_world` (no pose set), 0.5 px noise.
  Frame At(const SE3d& camera_from_world, FrameId id,
           std::vector<int>* point_of_keypoint = nullptr) const {
    return bow_.NoisyFrame(camera_from_world, id, 40 + id, point_of_keypoint);
  }
  // The last frame: at the fourth pose, posed, matched to the map's points.
  Frame LastFrame() const {
    std::vector<int> point_of_keypoint;
    Frame last = At(bow_.poses[3], 50, &point_of_keypoint);
    last.SetPose(bow_.poses[3]);
    for (int i = 0; i < last.size(); ++i) {
      last.map_points[i] = bow_.map.point_of_scene_index[point_of_keypoint[i]];
    }
    return last;
  }
  static SE3d Moved(const SE3d& pose, double metres) {
    return SE3d(SO3d::Exp(Eigen::Vector3d(0, 0.01, 0)), Eigen::Vector3d(metres, 0, 0)) * pose;
  }

  PoseOptimizerOptions pose_options_;
  testing::StereoBowMap bow_{800, 31, 4, 12};
};

TEST_F(FrameTrackingTest, TheLastFramesPointsAreFoundAroundThePredictedPose) {
  const Frame last = LastFrame();
  const SE3d truth = Moved(bow_.poses[3], 0.04);
  std::vector<int> point_of_keypoint;
  Frame frame = At(truth, 51, &point_of_keypoint);
  frame.SetPose(bow_.poses[3]);  // a constant-velocity guess 4 cm and 0.6 degrees off
  auto lock = MapReader(bow_.atlas).Lock();
  const int n = MatchLastFrame(last, 15.0, false, 20, &frame);
  ASSERT_GT(n, 100);
  int right = 0;
  for (int i = 0; i < frame.size(); ++i) {
    const MapPointPtr& mp = frame.map_points[i];
    if (mp) right += mp == bow_.map.point_of_scene_index[point_of_keypoint[i]] ? 1 : 0;
  }
  EXPECT_GE(right, static_cast<int>(0.98 * n));
  const int in_map = OptimizeAndDiscard(pose_options_, &frame);
  EXPECT_GE(in_map, static_cast<int>(0.95 * n));
  const SE3d error = frame.camera_from_world() * truth.Inverse();
  EXPECT_LT(error.translation().norm(), 0.01);
}

TEST_F(FrameTrackingTest, TooFewMatchesInTheWindowDoubleIt) {
  const Frame last = LastFrame();
  Frame frame = At(Moved(bow_.poses[3], 0.04), 51);
  frame.SetPose(bow_.poses[3]);
  auto lock = MapReader(bow_.atlas).Lock();
  Frame narrow = frame;
  const int in_narrow = MatchLastFrame(last, 2.0, false, 0, &narrow);  // never widened
  const int widened = MatchLastFrame(last, 2.0, false, in_narrow + 1, &frame);
  const int in_double = MatchLastFrame(last, 4.0, false, 0, &narrow);
  EXPECT_LT(in_narrow, widened);
  EXPECT_EQ(widened, in_double) << "the second search is the one at twice the radius";
}

TEST_F(FrameTrackingTest, AFrameIsTrackedToItsReferenceKeyframeThroughBow) {
  const SE3d truth = Moved(bow_.poses[2], 0.05);
  Frame frame = At(truth, 60);
  auto lock = MapReader(bow_.atlas).Lock();
  const KeyFrame& reference = *bow_.map.keyframes[2];
  const std::optional<int> in_map =
      TrackToKeyFrame(reference, bow_.vocabulary, bow_.poses[2], {0.7, 15}, pose_options_, &frame);
  ASSERT_TRUE(in_map.has_value());
  EXPECT_GT(*in_map, 100);
  EXPECT_LT((frame.camera_from_world() * truth.Inverse()).translation().norm(), 0.01);
  for (int i = 0; i < frame.size(); ++i) {
    if (frame.map_points[i]) {
      EXPECT_EQ(frame.outliers[i], 0);
    }
  }

  Frame unmatched = At(truth, 61);
  const std::optional<int> refused = TrackToKeyFrame(reference, bow_.vocabulary, bow_.poses[2],
                                                     {0.7, 100000}, pose_options_, &unmatched);
  EXPECT_FALSE(refused.has_value());
  for (const MapPointPtr& mp : unmatched.map_points) EXPECT_EQ(mp, nullptr);
}

TEST_F(FrameTrackingTest, AfterTheLocalMapOnlyInliersCountAndStereoDropsItsOutliers) {
  Frame mono = LastFrame();
  mono.outliers.assign(mono.size(), 0);
  std::vector<int> matched;
  for (int i = 0; i < mono.size(); ++i) {
    if (mono.map_points[i]) matched.push_back(i);
  }
  ASSERT_GT(matched.size(), 20u);
  const MapPointPtr flagged = mono.map_points[matched[0]];
  const MapPointPtr kept = mono.map_points[matched[1]];
  mono.outliers[matched[0]] = 1;
  mono.outliers[matched[2]] = 1;
  Frame stereo = mono;
  auto lock = MapReader(bow_.atlas).Lock();
  const int found_before = kept->found();
  const int flagged_found_before = flagged->found();
  EXPECT_EQ(CountLocalMapInliers(false, &mono), static_cast<int>(matched.size()) - 2);
  EXPECT_EQ(kept->found(), found_before + 1) << "an inlier was found once more";
  EXPECT_EQ(flagged->found(), flagged_found_before) << "an outlier was not";
  EXPECT_EQ(mono.map_points[matched[0]], flagged) << "monocular keeps the outlier's match";
  EXPECT_EQ(CountLocalMapInliers(true, &stereo), static_cast<int>(matched.size()) - 2);
  EXPECT_EQ(stereo.map_points[matched[0]], nullptr) << "stereo drops it";
  EXPECT_EQ(stereo.map_points[matched[1]], kept);

  DropOutlierMatches(&mono);
  EXPECT_EQ(mono.map_points[matched[0]], nullptr);
  EXPECT_EQ(mono.map_points[matched[2]], nullptr);
  EXPECT_EQ(mono.map_points[matched[1]], kept);
}

TEST_F(FrameTrackingTest, MatchesFollowFusedPointsAndForgetPointsOutsideTheMap) {
  Frame frame = LastFrame();
  frame.outliers.assign(frame.size(), 0);
  int first = -1;
  for (int i = 0; i < frame.size() && first < 0; ++i) {
    if (frame.map_points[i]) first = i;
  }
  ASSERT_GE(first, 0);
  const MapPointPtr temporary = MapPoint::Temporary(Eigen::Vector3d(0, 0, 3), Descriptor());
  frame.map_points[first] = temporary;
  frame.outliers[first] = 1;
  {
    auto lock = MapEditor(&bow_.atlas).Write(MapEdit::kFixture);
    FollowReplacedPoints(&frame);  // nothing fused yet: unchanged
    EXPECT_EQ(frame.map_points[first], temporary);
    DropUnmappedMatches(&frame);
    EXPECT_EQ(frame.map_points[first], nullptr) << "a point with no observations is dropped";
    EXPECT_EQ(frame.outliers[first], 0);
  }
  // A point fused into another (and that one into a third) is followed to the end of the chain.
  std::vector<int> matched;
  for (int i = first + 1; i < frame.size() && matched.size() < 3; ++i) {
    if (frame.map_points[i]) matched.push_back(i);
  }
  ASSERT_EQ(matched.size(), 3u);
  const MapPointPtr fused = frame.map_points[matched[0]];
  const MapPointPtr middle = frame.map_points[matched[1]];
  const MapPointPtr survivor = frame.map_points[matched[2]];
  auto lock = MapEditor(&bow_.atlas).Write(MapEdit::kFixture);
  fused->Replace(lock, middle);
  middle->Replace(lock, survivor);
  FollowReplacedPoints(&frame);
  EXPECT_EQ(frame.map_points[matched[0]], survivor);
  EXPECT_EQ(frame.map_points[matched[1]], survivor);
  EXPECT_EQ(frame.map_points[matched[2]], survivor);
}

}  // namespace
}  // namespace pkslam
