#include "dense/cloud_compare.h"

#include <gtest/gtest.h>

#include "core/util/error.h"

namespace pkslam::dense {
namespace {

// A 1 m x 1 m grid of points in the plane z = 0, 1 cm apart (101 x 101).
std::vector<Eigen::Vector3f> Grid() {
  std::vector<Eigen::Vector3f> g;
  for (int i = 0; i <= 100; ++i) {
    for (int j = 0; j <= 100; ++j) g.emplace_back(0.01f * i, 0.01f * j, 0.0f);
  }
  return g;
}

TEST(CloudCompareTest, SummaryOfHandMadeDistances) {
  const DistanceStats s = SummariseDistances({0.005f, 0.015f, 0.03f, 0.1f}, {0.01, 0.02, 0.05});
  EXPECT_EQ(s.count, 4u);
  EXPECT_NEAR(s.mean, 0.0375, 1e-7);
  EXPECT_NEAR(s.median, 0.0225, 1e-7);  // even count: mean of the middle two
  EXPECT_NEAR(s.rms, std::sqrt((0.005 * 0.005 + 0.015 * 0.015 + 0.03 * 0.03 + 0.01) / 4), 1e-7);
  EXPECT_NEAR(s.max, 0.1, 1e-7);
  EXPECT_EQ(s.within, (std::vector<double>{0.25, 0.5, 0.75}));
  EXPECT_NEAR(SummariseDistances({3.0f, 1.0f, 2.0f}, {}).median, 2.0, 1e-9);
  EXPECT_EQ(SummariseDistances({}, {0.01}).count, 0u);
}

TEST(CloudCompareTest, ShiftedCloudHasThatAccuracy) {
  const auto ref = Grid();
  std::vector<Eigen::Vector3f> cloud;
  for (const auto& p : ref) cloud.push_back(p + Eigen::Vector3f(0, 0, 0.015f));
  const CompareResult r = CompareClouds(cloud, ref, CompareOptions{});
  EXPECT_NEAR(r.accuracy.mean, 0.015, 1e-6);
  EXPECT_NEAR(r.accuracy.median, 0.015, 1e-6);
  EXPECT_EQ(r.accuracy.within, (std::vector<double>{0.0, 1.0, 1.0}));
  EXPECT_DOUBLE_EQ(r.completeness, 1.0);
}

TEST(CloudCompareTest, SurfaceAccuracyIgnoresTheSampleSpacing) {
  const auto ref = Grid();
  const std::vector<Eigen::Vector3f> normals(ref.size(), Eigen::Vector3f(0, 0, 1));
  // Points between the samples (half a spacing off in x and y) and 3 mm above the plane: the
  // nearest sample is 7.7 mm away, the surface 3 mm.
  std::vector<Eigen::Vector3f> cloud;
  for (int i = 10; i < 90; ++i) {
    for (int j = 10; j < 90; ++j)
      cloud.emplace_back(0.01f * i + 0.005f, 0.01f * j + 0.005f, 0.003f);
  }
  const CompareResult r = CompareClouds(cloud, ref, CompareOptions{}, {}, normals);
  EXPECT_NEAR(r.accuracy.mean, std::sqrt(0.005 * 0.005 * 2 + 0.003 * 0.003), 1e-5);
  ASSERT_TRUE(r.surface_accuracy.has_value());
  EXPECT_NEAR(r.surface_accuracy->mean, 0.003, 1e-5);
  EXPECT_EQ(r.surface_accuracy->count, cloud.size());
  EXPECT_FALSE(CompareClouds(cloud, ref, CompareOptions{}).surface_accuracy.has_value());
  EXPECT_THROW(CompareClouds(cloud, ref, CompareOptions{}, {}, {Eigen::Vector3f(0, 0, 1)}), Error);
}

TEST(CloudCompareTest, CompletenessCountsCoveredReferencePoints) {
  const auto ref = Grid();
  // The cloud covers x <= 0.3 only; reference points with x <= 0.34 are within 4.5 cm (a
  // threshold between grid columns, so float rounding cannot move a column across it).
  std::vector<Eigen::Vector3f> cloud;
  for (const auto& p : ref) {
    if (p.x() <= 0.3005f) cloud.push_back(p);
  }
  std::vector<std::uint8_t> left_half(ref.size(), 0);
  for (std::size_t i = 0; i < ref.size(); ++i) left_half[i] = ref[i].x() < 0.4995f;
  CompareOptions options;
  options.completeness_m = 0.045;
  const CompareResult r = CompareClouds(cloud, ref, options, left_half);
  EXPECT_NEAR(r.accuracy.max, 0.0, 1e-7);
  EXPECT_NEAR(r.completeness, 35.0 / 101.0, 1e-9);  // columns x = 0 .. 0.34
  ASSERT_TRUE(r.subset_completeness.has_value());
  EXPECT_EQ(*r.subset_points, 50u * 101u);
  EXPECT_NEAR(*r.subset_completeness, 35.0 / 50.0, 1e-9);
  EXPECT_NEAR(r.reference_to_cloud.max, 0.7, 1e-5);
}

TEST(CloudCompareTest, NearestDistancesAreExact) {
  const std::vector<Eigen::Vector3f> target = {{0, 0, 0}, {1, 0, 0}, {0, 2, 0}};
  const auto d = NearestDistances({{0.9f, 0.0f, 0.0f}, {0.0f, 1.5f, 0.0f}, {3, 4, 0}}, target);
  EXPECT_NEAR(d[0], 0.1, 1e-6);
  EXPECT_NEAR(d[1], 0.5, 1e-6);
  EXPECT_NEAR(d[2], std::sqrt(9.0 + 4.0), 1e-6);  // (0, 2, 0) is nearest
  EXPECT_THROW(NearestDistances(target, {}), Error);
  CompareOptions bad;
  bad.completeness_m = 0;
  EXPECT_THROW(CompareClouds(target, target, bad), OptionError);
}

TEST(CloudCompareTest, CompletenessAgainstAnotherReference) {
  // A 1 m x 1 m reference at 1 cm; the cloud covers its left 30 cm (within 5 cm: 35 cm).
  std::vector<Eigen::Vector3f> reference, cloud;
  for (int i = 0; i < 100; ++i) {
    for (int j = 0; j < 100; ++j) {
      const Eigen::Vector3f p(0.005f + 0.01f * i, 0.005f + 0.01f * j, 0.0f);
      reference.push_back(p);
      if (p.x() < 0.3f) cloud.push_back(p + Eigen::Vector3f(0, 0, 0.01f));
    }
  }
  EXPECT_NEAR(Completeness(cloud, reference, 0.05), 0.35, 0.011);
  EXPECT_NEAR(Completeness(cloud, reference, 0.005), 0.0, 1e-9);
  EXPECT_THROW(Completeness({}, reference, 0.05), Error);
  EXPECT_THROW(Completeness(cloud, reference, 0.0), Error);
}

}  // namespace
}  // namespace pkslam::dense
