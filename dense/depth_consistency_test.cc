#include "dense/depth_consistency.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/util/error.h"
#include "dense/dense_cloud.h"

namespace pkslam::dense {
namespace {

constexpr int kSmallW = 80, kSmallH = 60;

CameraModel SmallCamera() { return CameraModel::Pinhole(kSmallW, kSmallH, 60, 60, 39.5, 29.5); }

// Depth map of the plane z_world = wall_z seen by a camera at (x, 0, 0) looking along +z.
cv::Mat WallDepth(float wall_z) { return cv::Mat(kSmallH, kSmallW, CV_32FC1, cv::Scalar(wall_z)); }

SE3d CameraAt(double x) { return SE3d(SO3d(), Eigen::Vector3d(x, 0, 0)); }  // world_from_camera

TEST(DepthConsistencyTest, AgreeingViewsConfirmAndAverage) {
  const CameraModel camera = SmallCamera();
  const cv::Mat rays = RayTable(camera);
  const cv::Mat mine = WallDepth(2.01f);  // 1 cm too far
  const cv::Mat a = WallDepth(1.99f), b = WallDepth(2.0f);
  const std::vector<DepthView> neighbours = {{&a, CameraAt(0.1).Inverse()},
                                             {&b, CameraAt(-0.1).Inverse()}};
  ConsistencyOptions o;
  o.tolerance_rel = 0.02;
  const ConsistencyResult r =
      FilterByConsistency(mine, CameraAt(0), neighbours, rays, camera, 1, o);
  EXPECT_EQ(r.candidates, kSmallW * kSmallH);
  // The centre sees the wall in both neighbours: the mean of 2.01, 1.99, 2.00.
  EXPECT_NEAR(r.depth.at<float>(30, 40), 2.0f, 1e-4);
  // The outermost columns project outside one neighbour (0.1 m = 3 px at 2 m), still confirmed
  // by the other: with min_views 2 every pixel survives.
  EXPECT_EQ(r.kept, kSmallW * kSmallH);
  EXPECT_NEAR(r.depth.at<float>(30, 0), 0.5f * (2.01f + 2.0f), 1e-4);  // only b sees column 0
  // Three views needed: the columns only one neighbour sees go (strict filter), or stay
  // unaveraged as unconfirmed (nothing contradicts them).
  o.min_views = 3;
  const ConsistencyResult loose =
      FilterByConsistency(mine, CameraAt(0), neighbours, rays, camera, 1, o);
  EXPECT_EQ(loose.kept, kSmallW * kSmallH);
  EXPECT_GT(loose.unconfirmed, 0);
  EXPECT_EQ(loose.depth.at<float>(30, 0), 2.01f);
  EXPECT_EQ(loose.views.at<std::uint8_t>(30, 0), 1);
  o.keep_unconfirmed = false;
  const ConsistencyResult r3 =
      FilterByConsistency(mine, CameraAt(0), neighbours, rays, camera, 1, o);
  EXPECT_LT(r3.kept, kSmallW * kSmallH);
  EXPECT_GT(r3.kept, kSmallW * kSmallH * 3 / 4);
  EXPECT_EQ(r3.depth.at<float>(30, 0), 0.0f);
  EXPECT_GT(r3.depth.at<float>(30, 40), 0.0f);
  // Averaging off: the own depth stays.
  o.min_views = 2;
  o.keep_unconfirmed = true;
  o.average = false;
  EXPECT_EQ(FilterByConsistency(mine, CameraAt(0), neighbours, rays, camera, 1, o)
                .depth.at<float>(30, 40),
            2.01f);
}

TEST(DepthConsistencyTest, DisagreeingOrMissingDepthsDoNotConfirm) {
  const CameraModel camera = SmallCamera();
  const cv::Mat rays = RayTable(camera);
  cv::Mat mine = WallDepth(2.0f);
  mine.at<float>(10, 10) = 2.5f;     // an outlier no other view supports
  mine.at<float>(20, 20) = 0.0f;     // no depth
  cv::Mat other = WallDepth(2.05f);  // 2.5% off: outside a 1% tolerance
  const std::vector<DepthView> far_off = {{&other, CameraAt(0.05).Inverse()}};
  ConsistencyOptions o;
  o.tolerance_rel = 0.01;
  o.keep_unconfirmed = false;  // confirmations only (see the test below for the rest)
  EXPECT_EQ(FilterByConsistency(mine, CameraAt(0), far_off, rays, camera, 1, o).kept, 0);
  const cv::Mat good = WallDepth(2.0f);
  cv::Mat holes = WallDepth(0.0f);  // sees nothing: neither confirms nor rejects
  const std::vector<DepthView> views = {{&good, CameraAt(0.05).Inverse()},
                                        {&holes, CameraAt(-0.05).Inverse()}};
  const ConsistencyResult r = FilterByConsistency(mine, CameraAt(0), views, rays, camera, 1, o);
  EXPECT_EQ(r.candidates, kSmallW * kSmallH - 1);
  EXPECT_EQ(r.depth.at<float>(10, 10), 0.0f);
  EXPECT_EQ(r.depth.at<float>(20, 20), 0.0f);
  EXPECT_NEAR(r.depth.at<float>(30, 40), 2.0f, 1e-5);
  // A neighbour behind the camera does not confirm.
  const SE3d behind(SO3d::Exp(Eigen::Vector3d(0, M_PI, 0)), Eigen::Vector3d(0, 0, -1));
  const std::vector<DepthView> turned = {{&good, behind.Inverse()}};
  EXPECT_EQ(FilterByConsistency(mine, CameraAt(0), turned, rays, camera, 1, o).kept, 0);
  // min_views 1 keeps every depth without neighbours; pixel_step thins the grid.
  o.min_views = 1;
  const ConsistencyResult all = FilterByConsistency(mine, CameraAt(0), {}, rays, camera, 2, o);
  EXPECT_EQ(all.kept, (kSmallW / 2) * (kSmallH / 2) - 1);  // (20, 20) is on the grid and has no depth
  EXPECT_EQ(all.depth.at<float>(11, 11), 0.0f);
}

TEST(DepthConsistencyTest, UncontradictedSingleViewDepthsAreKeptUnconfirmed) {
  const CameraModel camera = SmallCamera();
  const cv::Mat rays = RayTable(camera);
  cv::Mat mine = WallDepth(2.0f);
  mine.at<float>(10, 60) = 1.6f;  // in front of the wall: the neighbour sees through it
  mine.at<float>(12, 70) = 2.5f;  // behind the wall that the neighbour sees on i's ray
  // The neighbour sees the wall except in its left half (a hole: no evidence either way).
  cv::Mat other = WallDepth(2.0f);
  other(cv::Rect(0, 0, kSmallW / 2, kSmallH)).setTo(0.0f);
  const std::vector<DepthView> views = {{&other, CameraAt(0.05).Inverse()}};
  ConsistencyOptions o;
  o.tolerance_rel = 0.02;
  const ConsistencyResult r = FilterByConsistency(mine, CameraAt(0), views, rays, camera, 1, o);
  // Where the neighbour has no depth, the wall is kept, unconfirmed (views 1, not averaged).
  EXPECT_EQ(r.depth.at<float>(30, 5), 2.0f);
  EXPECT_EQ(r.views.at<std::uint8_t>(30, 5), 1);
  // Confirmed pixels carry their view count.
  EXPECT_EQ(r.views.at<std::uint8_t>(30, 60), 2);
  // The two outliers project where the neighbour sees the wall: contradicted, dropped.
  EXPECT_EQ(r.depth.at<float>(10, 60), 0.0f);
  EXPECT_EQ(r.depth.at<float>(12, 70), 0.0f);
  EXPECT_EQ(r.contradicted, 2);
  EXPECT_EQ(r.kept, r.candidates - 2);
  // The strict filter drops every unconfirmed pixel.
  o.keep_unconfirmed = false;
  const ConsistencyResult strict =
      FilterByConsistency(mine, CameraAt(0), views, rays, camera, 1, o);
  EXPECT_EQ(strict.depth.at<float>(30, 5), 0.0f);
  EXPECT_EQ(strict.unconfirmed, 0);
  EXPECT_EQ(strict.kept, r.kept - r.unconfirmed);
}

TEST(DepthConsistencyTest, GenuineOcclusionDoesNotContradict) {
  const CameraModel camera = SmallCamera();
  const cv::Mat rays = RayTable(camera);
  // View i sees the wall at 2 m everywhere; view j (1 m to the side) has a post at 1 m in
  // front of part of the wall, which i does not see (it is off i's lines of sight there).
  const cv::Mat mine = WallDepth(2.0f);
  cv::Mat other = WallDepth(2.0f);
  other(cv::Rect(30, 0, 10, kSmallH)).setTo(1.0f);
  const std::vector<DepthView> views = {{&other, CameraAt(1.0).Inverse()}};
  ConsistencyOptions o;
  o.tolerance_rel = 0.02;
  const ConsistencyResult r = FilterByConsistency(mine, CameraAt(0), views, rays, camera, 1, o);
  EXPECT_EQ(r.contradicted, 0);
  EXPECT_EQ(r.kept, r.candidates);
}

TEST(DepthConsistencyTest, DeferRatioLeavesASurfaceToTheCloserView) {
  const CameraModel camera = SmallCamera();
  const cv::Mat rays = RayTable(camera);
  const cv::Mat mine = WallDepth(3.0f);
  const cv::Mat closer = WallDepth(1.5f);  // 1.5 m nearer the wall
  const SE3d closer_pose(SO3d(), Eigen::Vector3d(0, 0, 1.5));
  const std::vector<DepthView> views = {{&closer, closer_pose.Inverse()}};
  ConsistencyOptions o;
  o.tolerance_rel = 0.02;
  const ConsistencyResult kept = FilterByConsistency(mine, CameraAt(0), views, rays, camera, 1, o);
  EXPECT_GT(kept.kept, kSmallW * kSmallH / 5);  // the centre, which the closer view also sees
  EXPECT_EQ(kept.deferred, 0);
  o.defer_ratio = 1.5;
  const ConsistencyResult deferred =
      FilterByConsistency(mine, CameraAt(0), views, rays, camera, 1, o);
  EXPECT_EQ(deferred.deferred, kept.kept - kept.unconfirmed);  // every confirmed pixel
  EXPECT_EQ(deferred.depth.at<float>(30, 40), 0.0f);
  EXPECT_GT(deferred.depth.at<float>(2, 2), 0.0f);  // outside the closer view: kept
  o.defer_ratio = 2.5;                              // 3 m / 1.5 m = 2 < 2.5: keep
  EXPECT_EQ(FilterByConsistency(mine, CameraAt(0), views, rays, camera, 1, o).deferred, 0);
}

TEST(DepthConsistencyTest, AveragingShrinksIndependentNoise) {
  const CameraModel camera = SmallCamera();
  const cv::Mat rays = RayTable(camera);
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  auto noisy = [&] {
    cv::Mat d = WallDepth(2.0f);
    for (int r = 0; r < kSmallH; ++r) {
      for (int c = 0; c < kSmallW; ++c) d.at<float>(r, c) += noise(rng);
    }
    return d;
  };
  const cv::Mat mine = noisy();
  std::vector<cv::Mat> others;
  for (int k = 0; k < 6; ++k) others.push_back(noisy());
  std::vector<DepthView> views;
  for (int k = 0; k < 6; ++k) views.push_back({&others[k], CameraAt(0.01 * (k + 1)).Inverse()});
  ConsistencyOptions o;
  o.tolerance_rel = 0.05;
  const ConsistencyResult r = FilterByConsistency(mine, CameraAt(0), views, rays, camera, 1, o);
  double before = 0, after = 0;
  int n = 0;
  for (int row = 0; row < kSmallH; ++row) {
    for (int c = 0; c < kSmallW; ++c) {
      if (r.depth.at<float>(row, c) <= 0) continue;
      before += std::pow(mine.at<float>(row, c) - 2.0, 2);
      after += std::pow(r.depth.at<float>(row, c) - 2.0, 2);
      ++n;
    }
  }
  ASSERT_GT(n, kSmallW * kSmallH / 2);
  // Seven independent estimates: the RMS error drops by about sqrt(7).
  EXPECT_LT(std::sqrt(after / n), 0.5 * std::sqrt(before / n));
}

TEST(DepthConsistencyTest, BadInputThrows) {
  const CameraModel camera = SmallCamera();
  const cv::Mat rays = RayTable(camera);
  const cv::Mat d = WallDepth(2.0f);
  ConsistencyOptions o;
  o.tolerance_rel = 0;
  EXPECT_THROW(FilterByConsistency(d, CameraAt(0), {}, rays, camera, 1, o), OptionError);
  o = ConsistencyOptions{};
  o.min_views = 0;
  EXPECT_THROW(FilterByConsistency(d, CameraAt(0), {}, rays, camera, 1, o), OptionError);
  o = ConsistencyOptions{};
  const cv::Mat small(10, 10, CV_32FC1, cv::Scalar(1.0f));
  EXPECT_THROW(FilterByConsistency(d, CameraAt(0), {{&small, SE3d()}}, rays, camera, 1, o), Error);
  EXPECT_THROW(FilterByConsistency(small, CameraAt(0), {}, rays, camera, 1, o), Error);
}

}  // namespace
}  // namespace pkslam::dense
