#include "core/sensor/depth_uncertainty.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

namespace pkslam {
namespace {

constexpr double kK = 1.425e-3;  // Kinect v1
constexpr double kKinectBf = 36.75;  // 525 px * 0.07 m
constexpr double kScale = 1.0 / 5000.0;

cv::Mat Uniform(double z_m) {
  return cv::Mat(48, 64, CV_16U, cv::Scalar(static_cast<int>(std::lround(z_m / kScale))));
}

TEST(DepthUncertainty, FlatSurfaceGivesTheSensorNoise) {
  const DepthReading r = ReadKeypointDepth(Uniform(2.0), kScale, 20.3, 10.6, kK, 1.0, kKinectBf);
  EXPECT_FLOAT_EQ(r.depth, 2.0f);
  EXPECT_NEAR(r.sigma, kK * 4.0, 1e-9);
  // Quadratic noise is a constant disparity sigma: bf k.
  EXPECT_NEAR(1.0 / std::sqrt(DisparityInformation(kKinectBf, r.depth, r.sigma)), kKinectBf * kK,
              1e-6);
  const DepthReading far = ReadKeypointDepth(Uniform(4.0), kScale, 20, 10, kK, 1.0, kKinectBf);
  EXPECT_NEAR(1.0 / std::sqrt(DisparityInformation(kKinectBf, far.depth, far.sigma)),
              kKinectBf * kK, 1e-6);
}

TEST(DepthUncertainty, SlantedSurfaceAddsGradientTimesLocationSigma) {
  // Depth grows 1 cm per pixel along x (a strongly slanted wall at 2 m).
  cv::Mat depth(48, 64, CV_32F);
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) depth.at<float>(y, x) = 2.0f + 0.01f * (x - 20);
  }
  const DepthReading level0 = ReadKeypointDepth(depth, 1.0, 20, 10, kK, 1.0, kKinectBf);
  const DepthReading level4 =
      ReadKeypointDepth(depth, 1.0, 20, 10, kK, std::pow(1.2, 4), kKinectBf);
  const double sensor = kK * 4.0;
  EXPECT_NEAR(level0.sigma, std::sqrt(sensor * sensor + 1e-4 * (1.0 + 1.0 / 12)), 1e-6);
  EXPECT_GT(level4.sigma, level0.sigma);
  EXPECT_GT(level0.sigma, 2 * sensor);
}

TEST(DepthUncertainty, DiscontinuityAndHoleBordersAreDropped) {
  // Foreground box (1.5 m) in front of a wall (3 m): the pixel next to the edge.
  cv::Mat depth = Uniform(3.0);
  depth.colRange(0, 30).setTo(cv::Scalar(static_cast<int>(1.5 / kScale)));
  EXPECT_LE(ReadKeypointDepth(depth, kScale, 29, 10, kK, 1.0, kKinectBf).depth, 0.0f);
  EXPECT_LE(ReadKeypointDepth(depth, kScale, 30, 10, kK, 1.0, kKinectBf).depth, 0.0f);
  EXPECT_GT(ReadKeypointDepth(depth, kScale, 27, 10, kK, 1.0, kKinectBf).depth, 0.0f);
  // A 2 cm step at 2 m (a picture frame on a wall) is kept, with a larger sigma.
  cv::Mat step = Uniform(2.0);
  step.colRange(0, 30).setTo(cv::Scalar(static_cast<int>(1.98 / kScale)));
  const DepthReading s = ReadKeypointDepth(step, kScale, 30, 10, kK, 1.0, kKinectBf);
  EXPECT_GT(s.depth, 0.0f);
  EXPECT_GT(s.sigma, 1.5 * kK * 4.0);
  // Invalid (zero) pixels: the reading itself and its neighbours.
  cv::Mat holes = Uniform(2.0);
  holes.at<std::uint16_t>(10, 40) = 0;
  EXPECT_LE(ReadKeypointDepth(holes, kScale, 40, 10, kK, 1.0, kKinectBf).depth, 0.0f);
  EXPECT_LE(ReadKeypointDepth(holes, kScale, 41, 10, kK, 1.0, kKinectBf).depth, 0.0f);
  EXPECT_LE(ReadKeypointDepth(holes, kScale, 40.4, 9.2, kK, 1.0, kKinectBf).depth, 0.0f);
  EXPECT_GT(ReadKeypointDepth(holes, kScale, 42, 12, kK, 1.0, kKinectBf).depth, 0.0f);
  // Outside the image.
  EXPECT_LE(ReadKeypointDepth(holes, kScale, -1, 10, kK, 1.0, kKinectBf).depth, 0.0f);
  EXPECT_LE(ReadKeypointDepth(holes, kScale, 63.7, 10, kK, 1.0, kKinectBf).depth, 0.0f);
}

TEST(DepthUncertainty, ImageBorderUsesOneSidedDifferences) {
  const DepthReading r = ReadKeypointDepth(Uniform(1.0), kScale, 0, 0, kK, 1.0, kKinectBf);
  EXPECT_FLOAT_EQ(r.depth, 1.0f);
  EXPECT_NEAR(r.sigma, kK, 1e-9);
}

TEST(DepthUncertainty, NoInformationWithoutAReading) {
  EXPECT_EQ(DisparityInformation(kKinectBf, -1.0, 0.01), 0.0);
  EXPECT_EQ(DisparityInformation(kKinectBf, 2.0, -1.0), 0.0);
  EXPECT_GT(DisparityInformation(kKinectBf, 2.0, 0.01), 0.0);
}

}  // namespace
}  // namespace pkslam
