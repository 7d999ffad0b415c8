#include "core/geometry/point_cloud_index.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace pkslam {
namespace {

TEST(PointCloudIndex, FindsTheNearestPoint) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 500; ++i) points.emplace_back(u(rng), u(rng), u(rng));
  const PointCloudIndex index(points);
  for (int q = 0; q < 50; ++q) {
    const Eigen::Vector3f query(u(rng), u(rng), u(rng));
    int best = 0;
    for (int i = 1; i < 500; ++i) {
      if ((points[i] - query).squaredNorm() < (points[best] - query).squaredNorm()) best = i;
    }
    const auto [found, d2] = index.Nearest(query);
    EXPECT_EQ(found, best);
    EXPECT_NEAR(d2, (points[best] - query).squaredNorm(), 1e-6);
  }
  EXPECT_EQ(PointCloudIndex({}).Nearest(Eigen::Vector3f::Zero()).first, -1);
}

TEST(PointCloudIndex, AnyLeafSizeFindsTheSameNearestPoints) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 2000; ++i) points.emplace_back(u(rng), u(rng), u(rng));
  const PointCloudIndex small(points, 4);
  const PointCloudIndex large(points, 64);
  for (int q = 0; q < 200; ++q) {
    const Eigen::Vector3f query(u(rng), u(rng), u(rng));
    EXPECT_EQ(small.Nearest(query), large.Nearest(query));
  }
}

}  // namespace
}  // namespace pkslam
