#include "core/camera/fisheye_undistortion.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "core/camera/test_cameras.h"
#include "core/util/error.h"

namespace pkslam {
namespace {

TEST(FisheyeUndistortionTest, TumViPinholeViewFillsTheImage) {
  const FisheyeUndistortion u(testing::TumViKb8());
  const CameraModel& cam = u.pinhole_camera();
  EXPECT_EQ(cam.type(), CameraType::kPinhole);
  EXPECT_FALSE(cam.HasDistortion());
  EXPECT_EQ(cam.width(), 512);
  EXPECT_EQ(cam.height(), 512);
  // The lens's own scale at the centre.
  EXPECT_EQ(cam.fx(), 190.98);
  EXPECT_EQ(cam.fy(), 190.98);
  EXPECT_EQ(cam.cx(), 254.93);
  EXPECT_EQ(cam.cy(), 256.89);
  // Every pixel of the view was seen by the lens: the image corners map into the raw image.
  for (const Eigen::Vector2d& corner : {Eigen::Vector2d(0, 0), Eigen::Vector2d(511, 0),
                                       Eigen::Vector2d(0, 511), Eigen::Vector2d(511, 511)}) {
    const auto raw = u.DistortPixel(corner);
    ASSERT_TRUE(raw.has_value());
    EXPECT_TRUE(u.fisheye_camera().InImage(*raw)) << raw->transpose();
  }
}

TEST(FisheyeUndistortionTest, PixelMappingsAreInverse) {
  const FisheyeUndistortion u(testing::TumViKb8());
  for (double v = 0; v < 512; v += 37) {
    for (double x = 0; x < 512; x += 41) {
      const Eigen::Vector2d uv(x, v);
      const auto raw = u.DistortPixel(uv);
      ASSERT_TRUE(raw.has_value());
      const auto back = u.UndistortPixel(*raw);
      ASSERT_TRUE(back.has_value());
      EXPECT_NEAR((*back - uv).norm(), 0.0, 1e-6) << uv.transpose();
    }
  }
}

TEST(FisheyeUndistortionTest, RemapTablesAgreeWithThePixelMapping) {
  const FisheyeUndistortion u(testing::TumViKb8());
  for (int v = 3; v < 512; v += 51) {
    for (int x = 5; x < 512; x += 47) {
      const auto raw = u.DistortPixel(Eigen::Vector2d(x, v));
      ASSERT_TRUE(raw.has_value());
      EXPECT_NEAR(u.map_x().at<float>(v, x), raw->x(), 0.01);
      EXPECT_NEAR(u.map_y().at<float>(v, x), raw->y(), 0.01);
    }
  }
}

TEST(FisheyeUndistortionTest, ABlobLandsWherePinholeProjectionPutsIt) {
  const FisheyeUndistortion u(testing::TumViKb8());
  const Eigen::Vector3d point(0.4, -0.25, 1.0);  // off-axis, about 25 degrees
  const auto raw = u.fisheye_camera().Project(point);
  ASSERT_TRUE(raw.has_value());
  cv::Mat image(512, 512, CV_8UC1, cv::Scalar(0));
  cv::circle(image, cv::Point2d(raw->x(), raw->y()) * 16.0, 3 * 16, cv::Scalar(255), cv::FILLED,
             cv::LINE_AA, 4);
  const cv::Mat out = u.Undistort(image);
  const cv::Moments m = cv::moments(out, false);
  ASSERT_GT(m.m00, 0.0);
  const Eigen::Vector2d centroid(m.m10 / m.m00, m.m01 / m.m00);
  const auto expected = u.pinhole_camera().Project(point);
  ASSERT_TRUE(expected.has_value());
  // The blob is stretched by the view's changing scale, so its centroid is not exactly the
  // centre's image: a fraction of a pixel.
  EXPECT_LT((centroid - *expected).norm(), 0.3) << centroid.transpose() << " vs "
                                                << expected->transpose();
}

TEST(FisheyeUndistortionTest, RaysBeyondNinetyDegreesHaveNoPinholePixel) {
  const FisheyeUndistortion u(testing::TumViKb8());
  // TUM-VI's lens sees about 195 degrees: its image corners lie beyond 90 degrees.
  EXPECT_FALSE(u.UndistortPixel(Eigen::Vector2d(0, 0)).has_value());
}

TEST(FisheyeUndistortionTest, RejectsPinholeCamerasAndOtherImageSizes) {
  EXPECT_THROW(FisheyeUndistortion(testing::EurocCam0()), OptionError);
  const FisheyeUndistortion u(testing::TumViKb8());
  EXPECT_THROW(u.Undistort(cv::Mat(480, 752, CV_8UC1)), Error);
}

}  // namespace
}  // namespace pkslam
