#include "rgbd/feature_odometry.h"

#include <gtest/gtest.h>

#include <random>

#include "rgbd/test_scene.h"

namespace pkslam::rgbd {
namespace {

Descriptor RandomDescriptor(std::mt19937& rng) {
  Descriptor d;
  for (auto& b : d.bytes) b = static_cast<std::uint8_t>(rng() & 0xFF);
  return d;
}

TEST(MatchBruteForce, FindsPermutedDescriptorsAndKeepsTheBest) {
  std::mt19937 rng(3);
  std::vector<Descriptor> train;
  for (int i = 0; i < 50; ++i) train.push_back(RandomDescriptor(rng));
  std::vector<Descriptor> query;
  for (int i = 49; i >= 0; --i) query.push_back(train[i]);
  // Flip i bits of query i, so the distances are 0..49 and the best matches come first.
  for (int i = 0; i < 50; ++i) {
    for (int b = 0; b < i % 20; ++b) query[i].bytes[b] ^= 1;
  }
  const auto matches = MatchBruteForce(query, train, true, 256, 10);
  ASSERT_EQ(matches.size(), 10u);
  for (const auto& m : matches) {
    EXPECT_EQ(m.train, 49 - m.query);
    EXPECT_EQ(m.distance, m.query % 20);
  }
  for (std::size_t i = 1; i < matches.size(); ++i) {
    EXPECT_LE(matches[i - 1].distance, matches[i].distance);
  }
  // A distance cap removes the rest.
  EXPECT_EQ(MatchBruteForce(query, train, true, 0, 500).size(), 3u);  // i = 0, 20, 40
}

TEST(MatchBruteForce, CrossCheckDropsNonMutualMatches) {
  std::mt19937 rng(4);
  const Descriptor a = RandomDescriptor(rng);
  Descriptor a1 = a, a2 = a;
  a1.bytes[0] ^= 1;  // distance 1 from a
  a2.bytes[0] ^= 3;  // distance 2 from a
  const std::vector<Descriptor> train = {a};
  const std::vector<Descriptor> query = {a1, a2};  // both prefer train 0, which prefers a1
  EXPECT_EQ(MatchBruteForce(query, train, true, 256, 500).size(), 1u);
  EXPECT_EQ(MatchBruteForce(query, train, false, 256, 500).size(), 2u);
}

FeatureOdometryOptions TestOptions() {
  FeatureOdometryOptions o;
  o.orb.n_features = 800;
  o.depth.max_depth_m = 5.0;
  return o;
}

TEST(FeatureOdometry, RecoversTheCameraMotionOnTheSyntheticRoom) {
  const CameraModel camera = testing::TestCamera();
  FeatureOdometry odometry(camera, TestOptions(), testing::PathPose(0));
  for (int k = 0; k <= 6; k += 2) {
    const auto view = testing::RenderRoom(camera, testing::PathPose(k), 0.002, k + 1);
    const OdometryStep step = odometry.Process(view.colour_bgr, view.depth_m);
    if (k == 0) {
      EXPECT_EQ(step.status, OdometryStatus::kFirst);
      continue;
    }
    ASSERT_EQ(step.status, OdometryStatus::kTracked) << "frame " << k;
    EXPECT_GT(step.inliers, 50);
    EXPECT_LE(step.matches, 500);
    const SE3d error = testing::PathPose(k).Inverse() * step.world_from_camera;
    // ORB keypoints on coarse pyramid levels are a few pixels off (~1 cm on the walls), so
    // the frame-to-frame chain drifts by millimetres per step.
    EXPECT_LT(error.translation().norm(), 0.02) << "frame " << k;
    EXPECT_LT(error.so3().Angle() * 180 / M_PI, 0.5) << "frame " << k;
    EXPECT_GT(step.times.total(), 0.0);
  }
}

TEST(FeatureOdometry, MotionGateRejectsALargeStepAndKeepsTheReference) {
  const CameraModel camera = testing::TestCamera();
  FeatureOdometryOptions options = TestOptions();
  options.max_translation_m = 0.02;  // the 6-frame step below moves ~5 cm
  FeatureOdometry odometry(camera, options);
  const auto v0 = testing::RenderRoom(camera, testing::PathPose(0));
  const auto v6 = testing::RenderRoom(camera, testing::PathPose(6));
  const auto v1 = testing::RenderRoom(camera, testing::PathPose(1));
  EXPECT_EQ(odometry.Process(v0.colour_bgr, v0.depth_m).status, OdometryStatus::kFirst);
  const OdometryStep big = odometry.Process(v6.colour_bgr, v6.depth_m);
  EXPECT_EQ(big.status, OdometryStatus::kMotionGate);
  EXPECT_GT(big.step_translation_m, 0.02);
  // The next frame is matched against frame 0 (still the reference) and accepted.
  const OdometryStep small = odometry.Process(v1.colour_bgr, v1.depth_m);
  ASSERT_EQ(small.status, OdometryStatus::kTracked);
  const SE3d truth = testing::PathPose(0).Inverse() * testing::PathPose(1);
  EXPECT_LT((small.reference_from_current.translation() - truth.translation()).norm(), 0.005);
}

TEST(FeatureOdometry, TooManyRejectionsResetTheReference) {
  const CameraModel camera = testing::TestCamera();
  FeatureOdometryOptions options = TestOptions();
  options.max_consecutive_rejections = 1;
  FeatureOdometry odometry(camera, options);
  const auto room = testing::RenderRoom(camera, testing::PathPose(0));
  const cv::Mat flat(room.colour_bgr.size(), CV_8UC3, cv::Scalar(128, 128, 128));  // no features
  odometry.Process(room.colour_bgr, room.depth_m);
  EXPECT_EQ(odometry.Process(flat, room.depth_m).status, OdometryStatus::kTooFewMatches);
  EXPECT_EQ(odometry.Process(flat, room.depth_m).status, OdometryStatus::kReset);
}

}  // namespace
}  // namespace pkslam::rgbd
