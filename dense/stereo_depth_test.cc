#include "dense/stereo_depth.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <opencv2/imgproc.hpp>
#include <random>

#include "core/util/error.h"

namespace pkslam::dense {
namespace {

constexpr int kWidth = 752;
constexpr int kHeight = 480;

// Smooth random texture (what a textured simulator surface looks like to SGBM), CV_32F.
cv::Mat Texture(unsigned seed, int width) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 255.0f);
  cv::Mat noise(kHeight, width, CV_32F);
  for (int r = 0; r < noise.rows; ++r) {
    for (int c = 0; c < noise.cols; ++c) noise.at<float>(r, c) = u(rng);
  }
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 1.2);
  cv::normalize(noise, noise, 20, 235, cv::NORM_MINMAX);
  return noise;
}

// Bilinear sample of a CV_32F texture at column x (clamped).
float Sample(const cv::Mat& t, int row, double x) {
  x = std::clamp(x, 0.0, static_cast<double>(t.cols - 2));
  const int x0 = static_cast<int>(x);
  const double a = x - x0;
  return static_cast<float>((1 - a) * t.at<float>(row, x0) + a * t.at<float>(row, x0 + 1));
}

struct Pair {
  cv::Mat left, right;
  cv::Mat truth;  // left disparity, CV_32F
};

// A rectified pair of a scene whose left-image disparity is disparity(row, x): the texture
// is painted on the surface, so the right image at xr shows the left texture at xr + d.
// Surfaces are given per left pixel; `right_disparity(row, xr)` says which surface the right
// camera sees at xr (the nearest one).
Pair MakePair(const std::function<double(int, double)>& left_disparity,
              const std::function<double(int, double)>& right_disparity,
              const std::function<const cv::Mat*(int, double)>& texture_at_left_x) {
  Pair p;
  cv::Mat left(kHeight, kWidth, CV_32F), right(kHeight, kWidth, CV_32F);
  p.truth = cv::Mat(kHeight, kWidth, CV_32F);
  for (int r = 0; r < kHeight; ++r) {
    for (int c = 0; c < kWidth; ++c) {
      left.at<float>(r, c) = Sample(*texture_at_left_x(r, c), r, c);
      p.truth.at<float>(r, c) = static_cast<float>(left_disparity(r, c));
      const double d = right_disparity(r, c);
      right.at<float>(r, c) = Sample(*texture_at_left_x(r, c + d), r, c + d);
    }
  }
  left.convertTo(p.left, CV_8U);
  right.convertTo(p.right, CV_8U);
  return p;
}

TEST(StereoDepthTest, SlantedPlaneDisparityIsSubpixelAccurate) {
  const cv::Mat tex = Texture(1, kWidth + 200);
  // A slanted plane: disparity 12 px at the left edge rising to 30 px at the right.
  auto d = [](int row, double x) { return 12.0 + 18.0 * x / kWidth + 2.0 * row / kHeight; };
  // For the right view, solve xr + d(xl) = xl for the plane (d linear in x).
  auto dr = [](int row, double xr) {
    const double a = 18.0 / kWidth, b = 12.0 + 2.0 * row / kHeight;
    return (b + a * xr) / (1.0 - a);
  };
  const Pair p = MakePair(d, dr, [&](int, double) { return &tex; });
  StereoDepthOptions o;
  o.num_disparities = 48;
  const cv::Mat disp = ComputeDisparity(p.left, p.right, o);
  int valid = 0, total = 0;
  double abs_error = 0;
  for (int r = 10; r < kHeight - 10; ++r) {
    for (int c = o.num_disparities + 10; c < kWidth - 10; ++c) {
      ++total;
      const float v = disp.at<float>(r, c);
      if (v <= 0) continue;
      ++valid;
      abs_error += std::abs(v - p.truth.at<float>(r, c));
    }
  }
  EXPECT_GT(static_cast<double>(valid) / total, 0.9);
  EXPECT_LT(abs_error / valid, 0.25) << "mean |error| px";
  // The right view's disparity (mirrored matching) agrees with the plane's right disparity.
  const cv::Mat right = ComputeRightDisparity(p.left, p.right, o);
  int right_valid = 0;
  double right_error = 0;
  for (int r = 10; r < kHeight - 10; ++r) {
    for (int c = 10; c < kWidth - o.num_disparities - 10; ++c) {
      const float v = right.at<float>(r, c);
      if (v <= 0) continue;
      ++right_valid;
      right_error += std::abs(v - dr(r, c));
    }
  }
  EXPECT_GT(right_valid, total * 8 / 10);
  EXPECT_LT(right_error / right_valid, 0.25) << "mean |error| px, right view";
  // Depth follows bf / d.
  const cv::Mat depth = DisparityToDepth(disp, 48.0, 0.0);
  const float d0 = disp.at<float>(240, 400);
  ASSERT_GT(d0, 0);
  EXPECT_FLOAT_EQ(depth.at<float>(240, 400), 48.0f / d0);
  const cv::Mat clipped = DisparityToDepth(disp, 48.0, 48.0 / 25.0);  // keeps d >= 25 only
  EXPECT_EQ(clipped.at<float>(240, 100), 0.0f);                       // d ~ 15
  EXPECT_GT(clipped.at<float>(240, 700), 0.0f);                       // d ~ 29
}

TEST(StereoDepthTest, LeftRightCheckRemovesOccludedBackground) {
  const cv::Mat background = Texture(2, kWidth + 200);
  const cv::Mat foreground = Texture(3, kWidth + 200);
  // Background at disparity 8, a foreground slab at disparity 24 over left columns [300, 450).
  const double db = 8, df = 24;
  auto in_front = [](double xl) { return xl >= 300 && xl < 450; };
  auto d = [&](int, double x) { return in_front(x) ? df : db; };
  auto dr = [&](int, double xr) { return in_front(xr + df) ? df : db; };
  auto tex = [&](int, double xl) { return in_front(xl) ? &foreground : &background; };
  const Pair p = MakePair(d, dr, tex);
  StereoDepthOptions o;
  o.num_disparities = 48;
  // Even without the uniqueness test and the speckle filter the occluded pixels must go.
  o.uniqueness_ratio = 0;
  o.speckle_window_size = 0;
  // Background pixels x in [284, 300) map to right columns hidden by the slab: no right
  // pixel shows them, so no disparity there is confirmed by the right view.
  auto valid_in_band = [&](const cv::Mat& disp) {
    int valid = 0, n = 0;
    for (int r = 20; r < kHeight - 20; ++r) {
      for (int c = 286; c < 298; ++c) {
        ++n;
        valid += disp.at<float>(r, c) > 0;
      }
    }
    return static_cast<double>(valid) / n;
  };
  const cv::Mat checked = ComputeDisparity(p.left, p.right, o);
  EXPECT_LT(valid_in_band(checked), 0.1);
  // The check rejects little where both views see the surface.
  int valid = 0, n = 0;
  for (int r = 20; r < kHeight - 20; ++r) {
    for (int c = 80; c < 270; ++c) {
      ++n;
      valid += checked.at<float>(r, c) > 0;
    }
  }
  EXPECT_GT(static_cast<double>(valid) / n, 0.95);
  // Away from the edge both surfaces keep their disparities.
  EXPECT_NEAR(checked.at<float>(240, 380), df, 0.5);
  EXPECT_NEAR(checked.at<float>(240, 600), db, 0.5);
}

TEST(StereoDepthTest, PaddingRecoversBothImageSides) {
  const cv::Mat tex = Texture(4, kWidth + 200);
  // A fronto-parallel plane at disparity 16: every left pixel at x >= 16 has its match.
  const double disparity = 16;
  const Pair p =
      MakePair([&](int, double) { return disparity; }, [&](int, double) { return disparity; },
               [&](int, double) { return &tex; });
  StereoDepthOptions o;
  o.num_disparities = 64;
  // Valid share of the rows [20, 460) over left columns [c0, c1).
  auto valid_share = [&](const cv::Mat& disp, int c0, int c1) {
    int valid = 0, n = 0;
    for (int r = 20; r < kHeight - 20; ++r) {
      for (int c = c0; c < c1; ++c) {
        ++n;
        valid += std::abs(disp.at<float>(r, c) - disparity) < 0.5;
      }
    }
    return static_cast<double>(valid) / n;
  };
  const cv::Mat padded = ComputeDisparity(p.left, p.right, o);
  o.pad_borders = false;
  const cv::Mat unpadded = ComputeDisparity(p.left, p.right, o);
  // Left side: SGBM alone leaves the first num_disparities columns empty.
  EXPECT_LT(valid_share(unpadded, 24, 60), 0.05);
  EXPECT_GT(valid_share(padded, 24, 60), 0.9);
  // Right side: the mirrored right-view matching loses the right image's last
  // num_disparities columns, so the left-right check rejected the left pixels matching there.
  EXPECT_LT(valid_share(unpadded, kWidth - 40, kWidth - 10), 0.05);
  EXPECT_GT(valid_share(padded, kWidth - 40, kWidth - 10), 0.9);
  // No disparity points outside the right image.
  for (int r = 0; r < kHeight; ++r) {
    for (int c = 0; c < 16; ++c) EXPECT_LE(padded.at<float>(r, c), static_cast<float>(c));
  }
}

TEST(StereoDepthTest, LeftRightCheckByHand) {
  cv::Mat left = cv::Mat::zeros(1, 40, CV_32F), right = cv::Mat::zeros(1, 40, CV_32F);
  left.at<float>(0, 20) = 10.0f;  // right x = 10 agrees
  right.at<float>(0, 10) = 10.4f;
  left.at<float>(0, 30) = 5.0f;  // right x = 25 disagrees
  right.at<float>(0, 25) = 7.0f;
  left.at<float>(0, 3) = 6.0f;   // right x = -3: outside
  left.at<float>(0, 35) = 2.0f;  // right x = 33 has no disparity
  EXPECT_EQ(LeftRightCheck(right, 1.0, &left), 3);
  EXPECT_EQ(left.at<float>(0, 20), 10.0f);
  EXPECT_EQ(left.at<float>(0, 30), 0.0f);
  EXPECT_EQ(left.at<float>(0, 3), 0.0f);
  EXPECT_EQ(left.at<float>(0, 35), 0.0f);
}

TEST(StereoDepthTest, BadOptionsAndInputsThrow) {
  StereoDepthOptions o;
  o.num_disparities = 50;
  EXPECT_THROW(o.Check(), OptionError);
  o = {};
  o.block_size = 4;
  EXPECT_THROW(o.Check(), OptionError);
  const cv::Mat a(10, 20, CV_8U, cv::Scalar(0)), b(10, 21, CV_8U, cv::Scalar(0));
  EXPECT_THROW(ComputeDisparity(a, b, StereoDepthOptions{}), Error);
}

}  // namespace
}  // namespace pkslam::dense
