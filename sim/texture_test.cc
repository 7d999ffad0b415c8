#include "sim/texture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "sim/texture_factory.h"

namespace pkslam::sim {
namespace {

TEST(MipTexture, PyramidIsAlignedBoxFiltering) {
  // A 2x2 checker of 8x8 texels: every level's texel centres stay on the same grid, so the
  // coarse level at a cell centre equals the mean of the fine texels it covers.
  cv::Mat img(16, 16, CV_8UC1);
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) img.at<std::uint8_t>(y, x) = ((x / 8 + y / 8) % 2) ? 200 : 40;
  }
  const MipTexture tex(img, cv::Mat(), true);
  EXPECT_EQ(tex.num_levels(), 5);  // 16, 8, 4, 2, 1
  // Level 3 (2x2): texel (0,0) centre at s = t = 0.25 holds 40/255.
  EXPECT_NEAR(tex.SampleGrey(0.25f, 0.25f, 3.0f), 40.0f / 255.0f, 1e-6f);
  EXPECT_NEAR(tex.SampleGrey(0.75f, 0.25f, 3.0f), 200.0f / 255.0f, 1e-6f);
  // Level 4 (1x1) is the mean.
  EXPECT_NEAR(tex.SampleGrey(0.1f, 0.9f, 4.0f), 120.0f / 255.0f, 1e-6f);
  // Wrapping: s and s + 3 sample the same value.
  EXPECT_FLOAT_EQ(tex.SampleGrey(0.3f, 0.6f, 0.5f), tex.SampleGrey(3.3f, -0.4f, 0.5f));
  // The edge between two cells is half way at every level (no half-texel shift).
  for (float lod : {0.0f, 1.0f, 2.0f}) {
    EXPECT_NEAR(tex.SampleGrey(0.5f, 0.25f, lod), 120.0f / 255.0f, 1e-6f) << lod;
  }
}

TEST(MipTexture, ClampModeAndColour) {
  cv::Mat grey(4, 6, CV_8UC1, cv::Scalar(100));
  cv::Mat rgb(4, 6, CV_8UC3, cv::Scalar(10, 20, 30));
  const MipTexture tex(grey, rgb, false);
  EXPECT_EQ(tex.num_levels(), 2);  // 6x4 -> 3x2, then odd
  EXPECT_NEAR(tex.SampleGrey(-5.0f, 7.0f, 0.0f), 100.0f / 255.0f, 1e-6f);
  const Eigen::Vector3f c = tex.SampleColour(0.5f, 0.5f, 1.0f);
  EXPECT_NEAR(c.x(), 10.0f / 255.0f, 1e-6f);
  EXPECT_NEAR(c.z(), 30.0f / 255.0f, 1e-6f);
}

TEST(FastLog2, CloseToLog2) {
  for (float x = 1e-4f; x < 1e5f; x *= 1.37f) EXPECT_NEAR(FastLog2(x), std::log2(x), 0.01f) << x;
  EXPECT_EQ(FloorToInt(-0.5f), -1);
  EXPECT_EQ(FloorToInt(2.0f), 2);
  EXPECT_EQ(FloorToInt(-3.0f), -3);
}

TEST(TextureFactory, KindsHaveTheRequestedStatistics) {
  TextureSpec spec;
  spec.size = 256;
  spec.contrast = 0.18;
  const MipTexture noise = BuildTexture(spec, DefaultPhotoDir(), false);
  cv::Scalar mean, sd;
  cv::meanStdDev(noise.BaseGrey(), mean, sd);
  EXPECT_NEAR(mean[0], 127.5, 3.0);
  EXPECT_NEAR(sd[0], 0.18 * 255, 4.0);
  spec.kind = TextureKind::kWeak;
  spec.contrast = 0.03;
  cv::meanStdDev(BuildTexture(spec, DefaultPhotoDir(), false).BaseGrey(), mean, sd);
  EXPECT_LT(sd[0], 0.04 * 255);
  // A missing photograph falls back to noise (and says so).
  spec.kind = TextureKind::kPhoto;
  spec.photo = "no_such_photo.jpg";
  bool fallback = false;
  BuildTexture(spec, DefaultPhotoDir(), false, &fallback);
  EXPECT_TRUE(fallback);
  // Same seed, same texture.
  spec.kind = TextureKind::kNoise;
  const cv::Mat a = BuildTexture(spec, DefaultPhotoDir(), false).BaseGrey();
  const cv::Mat b = BuildTexture(spec, DefaultPhotoDir(), false).BaseGrey();
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace pkslam::sim
