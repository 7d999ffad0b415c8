#include "core/features/orb_descriptor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <utility>

#include "core/features/quadtree_distribution.h"
#include "core/features/synthetic_texture.h"

namespace pkslam {
namespace {

TEST(CircularPatch, HalfWidthsOfRadius15AreTheDiscAndSymmetric) {
  const std::vector<int> u_max = CircularPatchHalfWidths(15);
  const std::vector<int> expected = {15, 15, 15, 15, 14, 14, 14, 13, 13, 12, 11, 10, 9, 8, 6, 3};
  EXPECT_EQ(u_max, expected);
  // The disc {(u, v): |u| <= u_max[|v|]} equals its transpose, so rotating by 90 degrees maps
  // it onto itself.
  auto inside = [&](int u, int v) { return std::abs(u) <= u_max[std::abs(v)]; };
  for (int v = -15; v <= 15; ++v) {
    for (int u = -15; u <= 15; ++u) EXPECT_EQ(inside(u, v), inside(v, u)) << u << "," << v;
  }
}

TEST(OrientationDisc, EqualsTheMomentDefinition) {
  const cv::Mat image = SyntheticTexture(cv::Size(120, 90), 8);
  const std::vector<int> u_max = CircularPatchHalfWidths(15);
  const OrientationDisc disc(15);
  for (int y = 15; y < 75; y += 7) {
    for (int x = 15; x < 105; x += 9) {
      double m10 = 0.0;
      double m01 = 0.0;
      for (int v = -15; v <= 15; ++v) {
        for (int u = -u_max[std::abs(v)]; u <= u_max[std::abs(v)]; ++u) {
          m10 += u * image.at<std::uint8_t>(y + v, x + u);
          m01 += v * image.at<std::uint8_t>(y + v, x + u);
        }
      }
      double expected = std::atan2(m01, m10) * 180.0 / std::numbers::pi;
      if (expected < 0.0) expected += 360.0;
      EXPECT_NEAR(std::remainder(disc.Angle(image, {x, y}) - expected, 360.0), 0.0, 1e-3);
    }
  }
}

TEST(SmoothForDescriptor, BitExactWithOpenCvGaussian7x7Sigma2) {
  cv::RNG rng(3);
  for (const cv::Size size : {cv::Size(4, 4), cv::Size(5, 9), cv::Size(37, 41), cv::Size(3, 8),
                              cv::Size(161, 97), cv::Size(752, 480)}) {
    cv::Mat image(size, CV_8UC1);
    rng.fill(image, cv::RNG::UNIFORM, 0, 256);
    cv::Mat expected;
    cv::GaussianBlur(image, expected, cv::Size(7, 7), 2.0, 2.0, cv::BORDER_REFLECT_101);
    cv::Mat smoothed;
    SmoothForDescriptor(image, &smoothed);
    EXPECT_EQ(cv::countNonZero(smoothed != expected), 0) << size;
  }
  // Also on a view into a larger image (row stride != width).
  const cv::Mat big = SyntheticTexture(cv::Size(300, 200), 5);
  const cv::Mat roi = big(cv::Rect(13, 7, 201, 150));
  cv::Mat expected;
  cv::GaussianBlur(roi.clone(), expected, cv::Size(7, 7), 2.0, 2.0, cv::BORDER_REFLECT_101);
  cv::Mat smoothed;
  SmoothForDescriptor(roi, &smoothed);
  EXPECT_EQ(cv::countNonZero(smoothed != expected), 0);
}

TEST(OrientationDisc, PointsUpTheIntensityRamp) {
  const OrientationDisc disc(15);
  for (int deg = 0; deg < 360; deg += 15) {
    const double a = deg * std::numbers::pi / 180.0;
    cv::Mat image(41, 41, CV_8UC1);
    for (int y = 0; y < 41; ++y) {
      for (int x = 0; x < 41; ++x) {
        image.at<std::uint8_t>(y, x) = cv::saturate_cast<std::uint8_t>(
            128.0 + 4.0 * ((x - 20) * std::cos(a) + (y - 20) * std::sin(a)));
      }
    }
    const float angle = disc.Angle(image, {20, 20});
    EXPECT_GE(angle, 0.0f);
    EXPECT_LT(angle, 360.0f);
    const double diff = std::remainder(angle - deg, 360.0);
    EXPECT_NEAR(diff, 0.0, 1.0) << deg;
  }
}

TEST(RbriefPattern, TestsReachAtMost19PixelsForPatch31) {
  EXPECT_NEAR(RbriefPattern(31).MaxRadius(), std::hypot(13.0, 13.0), 1e-9);
  EXPECT_GT(RbriefPattern(45).MaxRadius(), RbriefPattern(31).MaxRadius());
}

// cv::ORB smooths each level in place as a view into its padded pyramid buffer; in OpenCV 4.6
// that call takes a different rounding path than cv::GaussianBlur on a whole image (which
// SmoothForDescriptor and ORB-SLAM reproduce bit for bit), so ~2% of smoothed pixels differ by
// one grey level. Replicates cv::ORB's smoothing for the exact comparison below.
cv::Mat SmoothLikeOpenCvOrb(const cv::Mat& image) {
  const int border = 23;  // max(edge 19, ceil(15 * sqrt 2), 9 / 2) + 1 for ORB(…, 19, …, 31)
  cv::Mat buffer(image.rows + 2 * border, (image.cols + 2 * border + 15) & -16, CV_8UC1);
  cv::Mat padded = buffer(cv::Rect(0, 0, image.cols + 2 * border, image.rows + 2 * border));
  cv::copyMakeBorder(image, padded, border, border, border, border, cv::BORDER_REFLECT_101);
  cv::Mat level = buffer(cv::Rect(border, border, image.cols, image.rows));
  cv::GaussianBlur(level, level, cv::Size(7, 7), 2.0, 2.0, cv::BORDER_REFLECT_101);
  return level.clone();
}

// The strongest check of pattern table, sampling and bit layout: cv::ORB::compute with the
// same keypoints (position and angle) on the same image gives the same bytes once the
// smoothed image is the same; with our own smoothing at most a few bits differ (sample pairs
// whose smoothed values tie or differ by one).
TEST(RbriefPattern, EqualsOpenCvOrbForSameKeypointsAndAngles) {
  const cv::Mat image = SyntheticTexture(cv::Size(320, 240), 11);
  std::vector<cv::KeyPoint> keypoints;
  cv::RNG rng(5);
  keypoints.reserve(410);
  for (int i = 0; i < 400; ++i) {
    keypoints.emplace_back(static_cast<float>(rng.uniform(19, 320 - 19)),
                           static_cast<float>(rng.uniform(19, 240 - 19)), 31.0f,
                           rng.uniform(0.0f, 360.0f), 1.0f, 0);
  }
  // Some angles where rounding ties are likely.
  for (float angle : {0.0f, 45.0f, 90.0f, 180.0f, 270.0f, 359.99f}) {
    keypoints.emplace_back(100.0f, 100.0f, 31.0f, angle, 1.0f, 0);
  }
  const cv::Ptr<cv::ORB> orb =
      cv::ORB::create(500, 1.2f, 1, /*edgeThreshold=*/19, 0, 2, cv::ORB::HARRIS_SCORE, 31, 20);
  std::vector<cv::KeyPoint> cv_keypoints = keypoints;
  cv::Mat cv_descriptors;
  orb->compute(image, cv_keypoints, cv_descriptors);
  ASSERT_EQ(cv_keypoints.size(), keypoints.size());

  const cv::Mat smoothed_like_cv = SmoothLikeOpenCvOrb(image);
  cv::Mat smoothed;
  SmoothForDescriptor(image, &smoothed);
  const RbriefPattern pattern(31);
  int equal_same_smoothing = 0;
  int equal_own_smoothing = 0;
  int max_bits_own_smoothing = 0;
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    ASSERT_EQ(cv_keypoints[i].pt, keypoints[i].pt);
    const cv::Point p(cvRound(keypoints[i].pt.x), cvRound(keypoints[i].pt.y));
    Descriptor theirs;
    std::memcpy(theirs.bytes.data(), cv_descriptors.ptr(static_cast<int>(i)), 32);
    const Descriptor same = pattern.Compute(smoothed_like_cv, p, keypoints[i].angle);
    const Descriptor own = pattern.Compute(smoothed, p, keypoints[i].angle);
    equal_same_smoothing += same == theirs ? 1 : 0;
    equal_own_smoothing += own == theirs ? 1 : 0;
    max_bits_own_smoothing = std::max(max_bits_own_smoothing, HammingDistance(own, theirs));
  }
  EXPECT_EQ(equal_same_smoothing, static_cast<int>(keypoints.size()));
  EXPECT_GE(equal_own_smoothing, static_cast<int>(0.8 * keypoints.size()));
  EXPECT_LE(max_bits_own_smoothing, 4);
}

// Rotating the image by exactly 90 degrees and the keypoint angle with it reproduces the
// descriptor bit for bit (the smoothing commutes with the rotation).
TEST(RbriefPattern, SteeredDescriptorFollowsA90DegreeRotation) {
  const cv::Mat image = SyntheticTexture(cv::Size(200, 160), 2);
  cv::Mat rotated;
  cv::rotate(image, rotated, cv::ROTATE_90_CLOCKWISE);  // (x, y) -> (H - 1 - y, x)
  cv::Mat s0, s1;
  SmoothForDescriptor(image, &s0);
  SmoothForDescriptor(rotated, &s1);
  const OrientationDisc disc(15);
  const RbriefPattern pattern(31);
  for (int y = 30; y < 130; y += 17) {
    for (int x = 30; x < 170; x += 23) {
      const cv::Point p(x, y);
      const cv::Point q(image.rows - 1 - y, x);
      const float a0 = disc.Angle(image, p);
      const float a1 = disc.Angle(rotated, q);
      EXPECT_NEAR(std::remainder(a1 - a0 - 90.0, 360.0), 0.0, 1e-3);
      EXPECT_EQ(pattern.Compute(s0, p, 0.0f), pattern.Compute(s1, q, 90.0f));
    }
  }
}

TEST(DistributeQuadtree, KeepsAllWhenFewerThanTarget) {
  std::vector<cv::KeyPoint> kps;
  kps.reserve(5);
  for (int i = 0; i < 5; ++i) kps.emplace_back(10.0f * i + 1, 7.0f, 7.0f, -1.0f, float(i));
  const std::vector<int> keep = DistributeQuadtree(kps, cv::Size(100, 60), 10);
  EXPECT_EQ(keep, (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_TRUE(DistributeQuadtree(kps, cv::Size(100, 60), 0).empty());
}

TEST(DistributeQuadtree, KeepsIsolatedPointsAndSamplesTheDenseCluster) {
  // 400 weak points in one corner and 4 isolated strong ones: the isolated ones sit alone in
  // their nodes and are always kept; the rest of the quota goes to the cluster.
  std::vector<cv::KeyPoint> kps;
  cv::RNG rng(1);
  kps.reserve(404);
  for (int i = 0; i < 400; ++i) {
    kps.emplace_back(rng.uniform(0.0f, 40.0f), rng.uniform(0.0f, 40.0f), 7.0f, -1.0f,
                     rng.uniform(1.0f, 50.0f));
  }
  const std::vector<int> isolated = {400, 401, 402, 403};
  for (const cv::Point2f p : {cv::Point2f(300, 210), cv::Point2f(500, 50), cv::Point2f(600, 350),
                              cv::Point2f(150, 310)}) {
    kps.emplace_back(p, 7.0f, -1.0f, 90.0f);
  }
  const int target = 20;
  const std::vector<int> keep = DistributeQuadtree(kps, cv::Size(640, 400), target);
  EXPECT_EQ(static_cast<int>(keep.size()), target);
  EXPECT_TRUE(std::is_sorted(keep.begin(), keep.end()));
  EXPECT_EQ(std::set<int>(keep.begin(), keep.end()).size(), keep.size());
  for (int i : isolated) EXPECT_TRUE(std::binary_search(keep.begin(), keep.end(), i)) << i;
}

TEST(DistributeQuadtree, OneKeypointPerClusterTheStrongest) {
  // 8 x 4 tight clusters of 3, one per 80 x 100 cell of a 640 x 400 area: two rounds of
  // splitting give exactly one node per cluster, which keeps its strongest member.
  std::vector<cv::KeyPoint> kps;
  std::vector<int> strongest;
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 8; ++i) {
      const float x = 80.0f * i + 30.0f;
      const float y = 100.0f * j + 40.0f;
      const int strong = (i + j) % 3;  // vary which member is strongest
      for (int m = 0; m < 3; ++m) {
        if (m == strong) strongest.push_back(static_cast<int>(kps.size()));
        kps.emplace_back(x + (m == 1 ? 1.0f : 0.0f), y + (m == 2 ? 1.0f : 0.0f), 7.0f, -1.0f,
                         m == strong ? 50.0f : 10.0f + m);
      }
    }
  }
  const std::vector<int> keep = DistributeQuadtree(kps, cv::Size(640, 400), 32);
  EXPECT_EQ(keep, strongest);
}

TEST(DistributeQuadtree, IsDeterministicUnderEqualResponses) {
  std::vector<cv::KeyPoint> kps;
  for (int y = 0; y < 50; ++y) {
    for (int x = 0; x < 80; ++x) kps.emplace_back(float(x), float(y), 7.0f, -1.0f, 10.0f);
  }
  const std::vector<int> a = DistributeQuadtree(kps, cv::Size(80, 50), 100);
  const std::vector<int> b = DistributeQuadtree(kps, cv::Size(80, 50), 100);
  EXPECT_EQ(a, b);
  EXPECT_EQ(a.size(), 100u);
}

}  // namespace
}  // namespace pkslam
