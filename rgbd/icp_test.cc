#include "rgbd/icp.h"

#include <gtest/gtest.h>

#include <random>

#include "rgbd/depth_cloud.h"
#include "rgbd/planar_frame.h"
#include "rgbd/test_scene.h"

namespace pkslam::rgbd {
namespace {

std::vector<Eigen::Vector3f> RoomCloud(const SE3d& world_from_camera, int stride, double noise = 0,
                                       unsigned seed = 1) {
  const CameraModel camera = testing::TestCamera();
  const auto view = testing::RenderRoom(camera, world_from_camera, noise, seed);
  return LiftDepthImage(view.depth_m, cv::Mat(), DepthLifter(camera), stride).points;
}

// Uniform random points on a room corner (floor, two walls) with a box: no grid to alias.
std::vector<Eigen::Vector3f> RandomCorner(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < n; ++i) {
    const float a = u(rng), b = u(rng);
    switch (i % 4) {
      case 0:
        points.emplace_back(-1.5f + 3 * a, 1.0f, 1.0f + 2 * b);
        break;  // floor
      case 1:
        points.emplace_back(-1.5f + 3 * a, -1.0f + 2 * b, 3.0f);
        break;  // front wall
      case 2:
        points.emplace_back(-1.5f, -1.0f + 2 * a, 1.0f + 2 * b);
        break;  // left wall
      default:
        points.emplace_back(0.2f + 0.4f * a, 0.6f + 0.4f * b, 2.0f);
        break;  // box face
    }
  }
  return points;
}

TEST(Icp, ConvergesToAKnownMotionOnSyntheticClouds) {
  const SE3d truth(SO3d::Exp(Eigen::Vector3d(0.01, -0.03, 0.02)),
                   Eigen::Vector3d(0.03, -0.02, 0.04));
  const PointCloudIndex target(RandomCorner(40000, 1));
  std::vector<Eigen::Vector3f> source;  // another sample of the same surfaces, moved
  for (const auto& p : RandomCorner(4000, 2)) {
    source.push_back((truth.Inverse() * p.cast<double>()).cast<float>());
  }
  IcpOptions options;
  options.max_iterations = 100;
  const IcpResult r = IcpPointToPoint(source, target, SE3d(), options);
  ASSERT_TRUE(r.success);
  EXPECT_TRUE(r.converged);
  const SE3d error = truth.Inverse() * r.target_from_source;
  EXPECT_LT(error.translation().norm(), 0.003);
  EXPECT_LT(error.so3().Angle() * 180 / M_PI, 0.1);
  EXPECT_LT(r.rmse_m, 0.02);  // ~2 cm sample spacing on the target
  EXPECT_EQ(r.correspondences, 4000);
}

TEST(Icp, AccelerationIsOptInAndJumpsAlongConsistentUpdates) {
  const SE3d truth(SO3d::Exp(Eigen::Vector3d(0.01, -0.03, 0.02)),
                   Eigen::Vector3d(0.03, -0.02, 0.04));
  const PointCloudIndex target(RandomCorner(40000, 1));
  std::vector<Eigen::Vector3f> source;
  for (const auto& p : RandomCorner(4000, 2)) {
    source.push_back((truth.Inverse() * p.cast<double>()).cast<float>());
  }
  IcpOptions options;
  options.max_iterations = 100;
  EXPECT_FALSE(options.accelerate);  // plain Besl-McKay ICP unless asked
  const IcpResult plain = IcpPointToPoint(source, target, SE3d(), options);
  EXPECT_EQ(plain.accelerations, 0);
  options.accelerate = true;
  const IcpResult accelerated = IcpPointToPoint(source, target, SE3d(), options);
  ASSERT_TRUE(accelerated.success);
  EXPECT_GT(accelerated.accelerations, 0);
  const SE3d error = truth.Inverse() * accelerated.target_from_source;
  EXPECT_LT(error.translation().norm(), 0.003);
}

TEST(Icp, ReducesTheErrorBetweenRenderedRoomViews) {
  // Different viewpoints: partial overlap and pixel grids that do not coincide.
  const SE3d world_from_a = testing::PathPose(0);
  const SE3d world_from_b = testing::PathPose(2);
  const SE3d truth = world_from_a.Inverse() * world_from_b;
  const PointCloudIndex target(RoomCloud(world_from_a, 1));
  const IcpResult r = IcpPointToPoint(RoomCloud(world_from_b, 2), target, SE3d(), IcpOptions());
  ASSERT_TRUE(r.success);
  const SE3d error = truth.Inverse() * r.target_from_source;
  EXPECT_LT(error.translation().norm(), 0.3 * truth.translation().norm());
  EXPECT_LT(error.translation().norm(), 0.01);
}

TEST(Icp, PlaneSamplesRegisterConsecutiveViews) {
  // The planar pipeline's use: samples of two frames, no point-to-point correspondence.
  const CameraModel camera = testing::TestCamera();
  const DepthLifter lifter(camera);
  const SE3d world_from_a = testing::PathPose(0), world_from_b = testing::PathPose(1);
  const auto va = testing::RenderRoom(camera, world_from_a, 0.003, 1);
  const auto vb = testing::RenderRoom(camera, world_from_b, 0.003, 2);
  const PlanarFrameOptions options;
  const PlanarFrame a = BuildPlanarFrame(va.colour_bgr, va.depth_m, lifter, options);
  const PlanarFrame b = BuildPlanarFrame(vb.colour_bgr, vb.depth_m, lifter, options);
  const IcpResult r = IcpPointToPoint(b.samples, PointCloudIndex(a.samples), SE3d(), IcpOptions());
  ASSERT_TRUE(r.success);
  const SE3d truth = world_from_a.Inverse() * world_from_b;
  EXPECT_LT((truth.Inverse() * r.target_from_source).translation().norm(), 0.03);
}

TEST(Icp, TooFewPointsFail) {
  const PointCloudIndex target(std::vector<Eigen::Vector3f>{{0, 0, 1}, {1, 0, 1}, {0, 1, 1}});
  const IcpResult r = IcpPointToPoint({{0, 0, 1}, {5, 5, 5}}, target, SE3d(), IcpOptions());
  EXPECT_FALSE(r.success);
}

}  // namespace
}  // namespace pkslam::rgbd
