#include "sim/depth_sensor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace pkslam::sim {
namespace {

TEST(KinectDepth, ExactWithoutNoise) {
  const cv::Mat z(8, 8, CV_32F, cv::Scalar(2.3456f));
  const PixelNoise noise;
  const cv::Mat d = KinectDepthImage(z, KinectDepthModel(), 0.0, noise, 1, 5000.0);
  EXPECT_EQ(d.at<std::uint16_t>(3, 3), 11728);
}

TEST(KinectDepth, OutOfRangeIsInvalid) {
  cv::Mat z(4, 4, CV_32F, cv::Scalar(3.0f));
  z.at<float>(0, 0) = 0.3f;
  z.at<float>(1, 1) = 9.0f;
  const PixelNoise noise;
  const cv::Mat d = KinectDepthImage(z, KinectDepthModel(), 1.0, noise, 1, 5000.0);
  EXPECT_EQ(d.at<std::uint16_t>(0, 0), 0);
  EXPECT_EQ(d.at<std::uint16_t>(1, 1), 0);
  EXPECT_GT(d.at<std::uint16_t>(2, 2), 0);
}

TEST(KinectDepth, QuantisedLevelsAndNoiseMatchTheModel) {
  // A flat wall at 3 m: readings take the sensor's discrete levels (2.6 cm apart at 3 m) and
  // scatter with the total sigma EffectiveNoiseK * z^2 (~1.5 cm).
  const KinectDepthModel model;
  const double z0 = 3.0;
  const cv::Mat z(200, 200, CV_32F, cv::Scalar(z0));
  const PixelNoise noise;
  const cv::Mat d = KinectDepthImage(z, model, 1.0, noise, 7, 5000.0);
  std::set<int> levels;
  double sum = 0, sum2 = 0;
  const int n = d.rows * d.cols;
  for (int y = 0; y < d.rows; ++y) {
    for (int x = 0; x < d.cols; ++x) {
      const double v = d.at<std::uint16_t>(y, x) / 5000.0;
      levels.insert(d.at<std::uint16_t>(y, x));
      sum += v;
      sum2 += v * v;
      // On a level: fb * steps / z is (close to) an integer.
      const double l = model.disparity_steps * model.disparity_fb / v;
      EXPECT_NEAR(l, std::round(l), 0.02) << v;
    }
  }
  const double mean = sum / n;
  const double sigma = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, z0, 0.002);
  EXPECT_NEAR(sigma, model.EffectiveNoiseK(1.0) * z0 * z0, 0.05 * sigma);
  EXPECT_GT(sigma, model.noise_k * z0 * z0);  // quantisation adds to the Gaussian error
  EXPECT_NEAR(model.LevelSpacing(z0), 0.0259, 0.0005);
  EXPECT_LT(levels.size(), 12u);  // a few levels, not a continuum
  EXPECT_GT(levels.size(), 3u);
}

}  // namespace
}  // namespace pkslam::sim
