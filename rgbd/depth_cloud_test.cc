#include "rgbd/depth_cloud.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "rgbd/test_scene.h"
#include "rgbd/voxel_map.h"
#include "tests/support/test_data.h"

namespace pkslam::rgbd {
namespace {

TEST(PreprocessDepth, GatesTheRangeAndKeepsInvalidPixelsInvalid) {
  cv::Mat depth(20, 20, CV_32FC1, cv::Scalar(2.0f));
  depth.at<float>(5, 5) = 0.5f;  // too close
  depth.at<float>(6, 6) = 4.0f;  // too far
  depth.at<float>(7, 7) = 0.0f;  // no measurement
  DepthFilterOptions options;
  const cv::Mat out = PreprocessDepth(depth, options);
  EXPECT_EQ(out.at<float>(5, 5), 0.0f);
  EXPECT_EQ(out.at<float>(6, 6), 0.0f);
  EXPECT_EQ(out.at<float>(7, 7), 0.0f);
  // Neighbours of invalid pixels are not pulled towards zero (range kernel).
  EXPECT_NEAR(out.at<float>(5, 6), 2.0f, 1e-4);
  EXPECT_NEAR(out.at<float>(10, 10), 2.0f, 1e-5);
}

TEST(PreprocessDepth, SmoothsNoiseButNotEdges) {
  cv::Mat depth(40, 40, CV_32FC1);
  cv::RNG rng(1);
  for (int v = 0; v < 40; ++v) {
    for (int u = 0; u < 40; ++u) {
      depth.at<float>(v, u) = (u < 20 ? 1.5f : 2.5f) + static_cast<float>(rng.gaussian(0.005));
    }
  }
  DepthFilterOptions options;
  const cv::Mat out = PreprocessDepth(depth, options);
  double raw_var = 0, filtered_var = 0;
  for (int v = 5; v < 35; ++v) {
    for (int u = 3; u < 15; ++u) {
      raw_var += std::pow(depth.at<float>(v, u) - 1.5, 2);
      filtered_var += std::pow(out.at<float>(v, u) - 1.5, 2);
    }
  }
  EXPECT_LT(filtered_var, 0.3 * raw_var);
  // Across the 1 m step nothing mixes.
  EXPECT_NEAR(out.at<float>(20, 19), 1.5f, 0.02);
  EXPECT_NEAR(out.at<float>(20, 20), 2.5f, 0.02);
}

TEST(DepthLifter, LiftsWithThePinholeFormula) {
  const CameraModel camera = CameraModel::Pinhole(64, 48, 50, 60, 30, 20);
  const DepthLifter lifter(camera);
  const Eigen::Vector3f p = lifter.LiftPixel(40, 10, 2.0f);
  EXPECT_NEAR(p.x(), (40 - 30) * 2.0 / 50, 1e-6);
  EXPECT_NEAR(p.y(), (10 - 20) * 2.0 / 60, 1e-6);
  EXPECT_FLOAT_EQ(p.z(), 2.0f);
  const Eigen::Vector3d q = lifter.Lift(40.5, 10.25, 2.0);
  EXPECT_NEAR(q.x(), 10.5 * 2.0 / 50, 1e-12);
}

TEST(DepthLifter, DistortedCameraPointsReprojectToTheirPixel) {
  const CameraModel camera = CameraModel::Pinhole(640, 480, 517.3, 516.5, 318.6, 255.3,
                                                  {0.2624, -0.9531, -0.0054, 0.0026, 1.1633});
  const DepthLifter lifter(camera);
  for (const auto& [u, v] : {std::pair{10, 10}, std::pair{600, 400}, std::pair{320, 240}}) {
    const Eigen::Vector3f p = lifter.LiftPixel(u, v, 1.7f);
    EXPECT_FLOAT_EQ(p.z(), 1.7f);
    const auto uv = camera.Project(p.cast<double>());
    ASSERT_TRUE(uv.has_value());
    EXPECT_NEAR(uv->x(), u, 1e-3);
    EXPECT_NEAR(uv->y(), v, 1e-3);
  }
}

TEST(LiftDepthImage, SkipsInvalidPixelsAndKeepsColours) {
  const CameraModel camera = testing::TestCamera();
  const auto view = testing::RenderRoom(camera, testing::PathPose(0));
  cv::Mat depth = view.depth_m.clone();
  depth(cv::Rect(0, 0, 100, 240)).setTo(0.0f);
  const ColouredCloud cloud = LiftDepthImage(depth, view.colour_bgr, DepthLifter(camera), 2);
  EXPECT_EQ(cloud.size(), static_cast<std::size_t>((320 - 100) / 2 * 120));
  for (std::size_t i = 0; i < cloud.size(); i += 97) {
    const int u = cloud.pixels[i] % 320, v = cloud.pixels[i] / 320;
    EXPECT_GE(u, 100);
    EXPECT_EQ(cloud.colours[i], view.colour_bgr.at<cv::Vec3b>(v, u));
    EXPECT_FLOAT_EQ(cloud.points[i].z(), depth.at<float>(v, u));
  }
}

TEST(VoxelMap, MergesPointsPerVoxelAndWritesPly) {
  VoxelMap map(0.1);
  map.Add(Eigen::Vector3d(0.01, 0.01, 0.01), cv::Vec3b(0, 0, 100));
  map.Add(Eigen::Vector3d(0.03, 0.05, 0.09), cv::Vec3b(0, 0, 200));
  map.Add(Eigen::Vector3d(-0.01, 0.01, 0.01), cv::Vec3b(10, 10, 10));
  EXPECT_EQ(map.size(), 2u);
  EXPECT_EQ(map.points_added(), 3u);
  const auto points = map.Points();
  ASSERT_EQ(points.size(), 2u);
  bool found = false;
  for (const auto& p : points) {
    if (p.position.x() > 0) {
      EXPECT_NEAR(p.position.x(), 0.02, 1e-6);
      EXPECT_EQ(p.bgr[2], 150);
      found = true;
    }
  }
  EXPECT_TRUE(found);
  const auto dir = pkslam::testing::MakeTempDir("voxel_map");
  map.WritePly(dir / "map.ply");
  std::ifstream in(dir / "map.ply", std::ios::binary);
  std::string header((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(header.find("element vertex 2"), std::string::npos);
  const auto end = header.find("end_header\n");
  ASSERT_NE(end, std::string::npos);
  EXPECT_EQ(header.size() - end - 11, 2u * 15u);  // 3 floats + 3 bytes each
}

}  // namespace
}  // namespace pkslam::rgbd
