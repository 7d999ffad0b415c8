#include "rgbd/region_growing.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "rgbd/kmeans_segmentation.h"
#include "rgbd/test_scene.h"

namespace pkslam::rgbd {
namespace {

TEST(BgrToLab, GivesCieLabUnits) {
  cv::Mat bgr(1, 3, CV_8UC3);
  bgr.at<cv::Vec3b>(0, 0) = {255, 255, 255};
  bgr.at<cv::Vec3b>(0, 1) = {0, 0, 0};
  bgr.at<cv::Vec3b>(0, 2) = {0, 0, 255};  // sRGB red: L 53.2, a 80.1, b 67.2
  const cv::Mat lab = BgrToLab(bgr);
  EXPECT_NEAR(lab.at<cv::Vec3f>(0, 0)[0], 100.0, 0.1);
  EXPECT_NEAR(lab.at<cv::Vec3f>(0, 1)[0], 0.0, 0.1);
  EXPECT_NEAR(lab.at<cv::Vec3f>(0, 2)[0], 53.2, 0.3);
  EXPECT_NEAR(lab.at<cv::Vec3f>(0, 2)[1], 80.1, 0.5);
  EXPECT_NEAR(lab.at<cv::Vec3f>(0, 2)[2], 67.2, 0.5);
}

TEST(RegionGrowing, TwoColourImageGivesExactlyTwoSegments) {
  // A red disc on a blue background: two segments, pixel-exact, 8-connected.
  cv::Mat bgr(60, 80, CV_8UC3, cv::Scalar(200, 40, 30));
  cv::circle(bgr, cv::Point(40, 30), 15, cv::Scalar(30, 30, 220), cv::FILLED);
  const Segmentation seg = SegmentRegionGrowing(BgrToLab(bgr), 15);
  ASSERT_EQ(seg.count, 2);
  const int background = seg.labels.at<int>(0, 0);
  const int disc = seg.labels.at<int>(30, 40);
  EXPECT_NE(background, disc);
  for (int v = 0; v < bgr.rows; ++v) {
    for (int u = 0; u < bgr.cols; ++u) {
      const bool red = bgr.at<cv::Vec3b>(v, u)[2] == 220;
      EXPECT_EQ(seg.labels.at<int>(v, u), red ? disc : background) << u << "," << v;
    }
  }
}

TEST(RegionGrowing, EightConnectivityJoinsDiagonalPixels) {
  // A diagonal line of one colour on another: one segment for the line (8-connected).
  cv::Mat bgr(10, 10, CV_8UC3, cv::Scalar(255, 255, 255));
  for (int i = 0; i < 10; ++i) bgr.at<cv::Vec3b>(i, i) = {0, 0, 0};
  const Segmentation seg = SegmentRegionGrowing(BgrToLab(bgr), 10);
  // The two white triangles also touch diagonally (across the line): 2 segments in all.
  EXPECT_EQ(seg.count, 2);
  EXPECT_EQ(seg.labels.at<int>(0, 1), seg.labels.at<int>(1, 0));
  for (int i = 1; i < 10; ++i) EXPECT_EQ(seg.labels.at<int>(i, i), seg.labels.at<int>(0, 0));
}

TEST(RegionGrowing, ThresholdControlsTheSegmentCount) {
  // Vertical stripes whose Lab distance to the neighbour is ~8: one segment at threshold 30
  // (running mean stays within reach), one per stripe at threshold 5.
  cv::Mat bgr(20, 40, CV_8UC3);
  for (int u = 0; u < 40; ++u) {
    const auto g = static_cast<unsigned char>(100 + 20 * ((u / 10) % 2));
    bgr.col(u).setTo(cv::Scalar(g, g, g));
  }
  EXPECT_EQ(SegmentRegionGrowing(BgrToLab(bgr), 30).count, 1);
  EXPECT_EQ(SegmentRegionGrowing(BgrToLab(bgr), 5).count, 4);
}

TEST(RegionGrowing, MaskedPixelsStayUnlabelled) {
  cv::Mat bgr(10, 10, CV_8UC3, cv::Scalar(50, 50, 50));
  cv::Mat mask(10, 10, CV_8UC1, cv::Scalar(255));
  mask.col(5).setTo(0);  // splits the image in two
  const Segmentation seg = SegmentRegionGrowing(BgrToLab(bgr), 10, mask);
  EXPECT_EQ(seg.count, 2);
  EXPECT_EQ(seg.labels.at<int>(3, 5), -1);
}

TEST(KMeansSegmentation, BaselineRunsAndLabelsEveryPoint) {
  const CameraModel camera = testing::TestCamera();
  const auto view = testing::RenderRoom(camera, testing::PathPose(0));
  const ColouredCloud cloud = LiftDepthImage(view.depth_m, view.colour_bgr, DepthLifter(camera));
  KMeansOptions options;
  options.clusters = 30;
  options.stride = 4;
  const Segmentation seg = SegmentKMeans(cloud, view.depth_m.size(), options);
  EXPECT_EQ(seg.count, 30);
  std::vector<int> sizes(30, 0);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int label = seg.labels.ptr<int>(0)[cloud.pixels[i]];
    ASSERT_GE(label, 0);
    ASSERT_LT(label, 30);
    ++sizes[label];
  }
  EXPECT_GT(*std::min_element(sizes.begin(), sizes.end()), 0);
  // Same seed, same labels.
  const Segmentation again = SegmentKMeans(cloud, view.depth_m.size(), options);
  EXPECT_EQ(cv::countNonZero(seg.labels != again.labels), 0);
}

}  // namespace
}  // namespace pkslam::rgbd
