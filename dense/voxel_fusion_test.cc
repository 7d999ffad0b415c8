#include "dense/voxel_fusion.h"

#include <gtest/gtest.h>

#include <random>

#include "core/util/error.h"

namespace pkslam::dense {
namespace {

TEST(VoxelFusionTest, AveragesPositionsAndColoursPerVoxel) {
  VoxelGrid grid(0.1);
  grid.AddView(0, {{0.01f, 0.02f, 0.03f}, {0.05f, 0.06f, 0.07f}}, {{10, 20, 30}, {30, 40, 50}});
  grid.AddView(1, {{0.09f, 0.01f, 0.02f}}, {{80, 0, 10}});
  ASSERT_EQ(grid.NumVoxels(), 1u);
  const PointCloud c = grid.Extract(2);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_NEAR(c.points[0].x(), (0.01 + 0.05 + 0.09) / 3, 1e-6);
  EXPECT_NEAR(c.points[0].y(), (0.02 + 0.06 + 0.01) / 3, 1e-6);
  EXPECT_NEAR(c.points[0].z(), (0.03 + 0.07 + 0.02) / 3, 1e-6);
  EXPECT_EQ(c.colours[0], (Rgb{40, 20, 30}));
  EXPECT_EQ(c.views[0], 2);
}

TEST(VoxelFusionTest, MultiViewFilterKeepsOnlyConfirmedVoxels) {
  VoxelGrid grid(0.01);
  // View 0: two points in different voxels; view 1 confirms only the first; view 0's
  // many points in one voxel still count as one view.
  grid.AddView(0, {{0.005f, 0.005f, 0.005f}, {0.5f, 0.5f, 0.5f}, {0.5f, 0.501f, 0.5f}}, {});
  grid.AddView(1, {{0.004f, 0.006f, 0.002f}}, {});
  EXPECT_EQ(grid.NumVoxels(), 2u);
  EXPECT_EQ(grid.Extract(1).size(), 2u);
  const PointCloud two = grid.Extract(2);
  ASSERT_EQ(two.size(), 1u);
  EXPECT_LT(two.points[0].norm(), 0.01f);
  EXPECT_FALSE(two.has_colour());
  EXPECT_EQ(grid.Extract(3).size(), 0u);
  const auto histogram = grid.ViewHistogram(4);
  EXPECT_EQ(histogram[1], 1u);
  EXPECT_EQ(histogram[2], 1u);
  // The same view id again in a consecutive call is the same view.
  grid.AddView(1, {{0.5f, 0.5f, 0.5f}}, {});
  EXPECT_EQ(grid.Extract(2).size(), 2u);
}

TEST(VoxelFusionTest, NegativeCoordinatesUseFloorAndExtractionIsOrdered) {
  VoxelGrid grid(0.05);
  grid.AddView(0, {{-0.01f, -0.01f, -0.01f}, {0.01f, 0.01f, 0.01f}}, {});
  grid.AddView(1, {{-0.02f, -0.02f, -0.02f}, {0.02f, 0.02f, 0.02f}}, {});
  const PointCloud c = grid.Extract(2);
  ASSERT_EQ(c.size(), 2u);  // -0.01 and 0.01 fall in different voxels
  EXPECT_LT(c.points[0].x(), 0.0f);
  EXPECT_NEAR(c.points[0].x(), -0.015, 1e-6);
  EXPECT_NEAR(c.points[1].x(), 0.015, 1e-6);
}

TEST(VoxelFusionTest, NoisyViewsOfAPlaneAverageTowardsIt) {
  // Ten views of the plane z = 2 with 5 mm noise: the fused points lie closer to the plane.
  std::mt19937 rng(4);
  std::normal_distribution<float> noise(0.0f, 0.005f);
  VoxelGrid grid(0.02);
  for (int view = 0; view < 10; ++view) {
    std::vector<Eigen::Vector3f> pts;
    for (int i = 0; i < 50; ++i) {
      for (int j = 0; j < 50; ++j)
        pts.emplace_back(0.01f * i + 0.001f, 0.01f * j + 0.001f, 2.01f + noise(rng));
    }
    grid.AddView(view, pts, {});
  }
  const PointCloud c = grid.Extract(5);
  ASSERT_GT(c.size(), 100u);
  double rms = 0;
  for (const auto& p : c.points) rms += (p.z() - 2.01) * (p.z() - 2.01);
  rms = std::sqrt(rms / c.size());
  EXPECT_LT(rms, 0.003);
}

TEST(VoxelFusionTest, BadInputThrows) {
  EXPECT_THROW(VoxelGrid(0.0), OptionError);
  VoxelGrid grid(0.01);
  EXPECT_THROW(grid.AddView(0, {{1, 2, 3}}, {{1, 2, 3}, {4, 5, 6}}), Error);
  EXPECT_THROW(grid.AddView(0, {{1e5f, 0, 0}}, {}), Error);  // beyond 2^20 voxels
}

}  // namespace
}  // namespace pkslam::dense
