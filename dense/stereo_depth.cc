#include "dense/stereo_depth.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "core/util/error.h"

namespace pkslam::dense {
namespace {

cv::Ptr<cv::StereoSGBM> MakeMatcher(const StereoDepthOptions& o) {
  const int area = o.block_size * o.block_size;  // grey images: one channel
  const int p1 = o.p1 > 0 ? o.p1 : 8 * area;
  const int p2 = o.p2 > 0 ? o.p2 : 32 * area;
  // disp12MaxDiff -1: OpenCV's own (one-sided) left-right check is off; ours is below.
  return cv::StereoSGBM::create(
      o.min_disparity, o.num_disparities, o.block_size, p1, p2,
      /*disp12MaxDiff=*/-1, /*preFilterCap=*/31, o.uniqueness_ratio, o.speckle_window_size,
      o.speckle_range, o.three_way ? cv::StereoSGBM::MODE_SGBM_3WAY : cv::StereoSGBM::MODE_SGBM);
}

// SGBM's fixed-point output (16 * d; below min_disparity * 16 = invalid) as float pixels.
cv::Mat ToFloatDisparity(const cv::Mat& fixed, int min_disparity) {
  cv::Mat out(fixed.size(), CV_32FC1);
  const int invalid_below = min_disparity * 16;
  for (int r = 0; r < fixed.rows; ++r) {
    const auto* src = fixed.ptr<std::int16_t>(r);
    auto* dst = out.ptr<float>(r);
    for (int c = 0; c < fixed.cols; ++c) {
      dst[c] = src[c] < invalid_below || src[c] <= 0 ? 0.0f : static_cast<float>(src[c]) / 16.0f;
    }
  }
  return out;
}

void CheckPair(const cv::Mat& left, const cv::Mat& right) {
  PKSLAM_CHECK(!left.empty() && left.size() == right.size(), "stereo images differ in size");
  PKSLAM_CHECK(left.type() == CV_8UC1 && right.type() == CV_8UC1,
               "stereo matching needs 8-bit grey images");
}

}  // namespace

void StereoDepthOptions::Check() const {
  PKSLAM_CHECK_OPTION(min_disparity >= 0, "min_disparity", "{}", min_disparity);
  PKSLAM_CHECK_OPTION(num_disparities > 0 && num_disparities % 16 == 0, "num_disparities",
                      "{} is not a positive multiple of 16", num_disparities);
  PKSLAM_CHECK_OPTION(block_size >= 1 && block_size <= 11 && block_size % 2 == 1, "block_size",
                      "{} is not odd in [1, 11]", block_size);
  PKSLAM_CHECK_OPTION(p1 >= 0 && p2 >= 0 && (p1 == 0 || p2 == 0 || p2 > p1), "p1/p2", "p1 {} p2 {}",
                      p1, p2);
  PKSLAM_CHECK_OPTION(uniqueness_ratio >= 0 && uniqueness_ratio < 100, "uniqueness_ratio", "{}",
                      uniqueness_ratio);
  PKSLAM_CHECK_OPTION(speckle_window_size >= 0 && speckle_range >= 0, "speckle",
                      "window {} range {}", speckle_window_size, speckle_range);
}

cv::Mat ComputeRawDisparity(const cv::Mat& rect_left, const cv::Mat& rect_right,
                            const StereoDepthOptions& options) {
  options.Check();
  CheckPair(rect_left, rect_right);
  cv::Mat fixed;
  if (!options.pad_borders) {
    MakeMatcher(options)->compute(rect_left, rect_right, fixed);
    return ToFloatDisparity(fixed, options.min_disparity);
  }
  const int pad = options.min_disparity + options.num_disparities;
  cv::Mat left, right;
  cv::copyMakeBorder(rect_left, left, 0, 0, pad, 0, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::copyMakeBorder(rect_right, right, 0, 0, pad, 0, cv::BORDER_CONSTANT, cv::Scalar(0));
  MakeMatcher(options)->compute(left, right, fixed);
  cv::Mat disparity = ToFloatDisparity(fixed(cv::Rect(pad, 0, rect_left.cols, rect_left.rows)),
                                       options.min_disparity);
  // A match inside the padding is no match.
  for (int r = 0; r < disparity.rows; ++r) {
    float* d = disparity.ptr<float>(r);
    for (int c = 0; c < disparity.cols; ++c) {
      if (d[c] > static_cast<float>(c)) d[c] = 0;
    }
  }
  return disparity;
}

int LeftRightCheck(const cv::Mat& right_disparity, double max_difference, cv::Mat* left_disparity) {
  PKSLAM_CHECK(left_disparity != nullptr && left_disparity->type() == CV_32FC1 &&
                   right_disparity.type() == CV_32FC1 &&
                   left_disparity->size() == right_disparity.size(),
               "LeftRightCheck needs two CV_32FC1 maps of one size");
  int removed = 0;
  for (int r = 0; r < left_disparity->rows; ++r) {
    auto* dl = left_disparity->ptr<float>(r);
    const auto* dr = right_disparity.ptr<float>(r);
    for (int c = 0; c < left_disparity->cols; ++c) {
      if (dl[c] <= 0) continue;
      // The right pixel this left pixel matched; its own disparity must point back here.
      const long xr = std::lround(static_cast<double>(c) - dl[c]);
      const bool ok = xr >= 0 && dr[xr] > 0 && std::abs(dl[c] - dr[xr]) <= max_difference;
      if (!ok) {
        dl[c] = 0;
        ++removed;
      }
    }
  }
  return removed;
}

cv::Mat ComputeRightDisparity(const cv::Mat& rect_left, const cv::Mat& rect_right,
                              const StereoDepthOptions& options) {
  cv::Mat mirrored_left, mirrored_right;
  cv::flip(rect_left, mirrored_left, 1);
  cv::flip(rect_right, mirrored_right, 1);
  // In the mirrored pair the right image plays the left role.
  const cv::Mat mirrored = ComputeRawDisparity(mirrored_right, mirrored_left, options);
  cv::Mat right;
  cv::flip(mirrored, right, 1);
  return right;
}

cv::Mat ComputeDisparity(const cv::Mat& rect_left, const cv::Mat& rect_right,
                         const StereoDepthOptions& options) {
  cv::Mat left = ComputeRawDisparity(rect_left, rect_right, options);
  if (options.lr_max_difference < 0) return left;
  const cv::Mat right = ComputeRightDisparity(rect_left, rect_right, options);
  LeftRightCheck(right, options.lr_max_difference, &left);
  return left;
}

cv::Mat DisparityToDepth(const cv::Mat& disparity, double bf, double max_depth_m) {
  PKSLAM_CHECK(disparity.type() == CV_32FC1, "disparity must be CV_32FC1");
  PKSLAM_CHECK(bf > 0, "bf {} <= 0", bf);
  cv::Mat depth(disparity.size(), CV_32FC1, cv::Scalar(0));
  for (int r = 0; r < disparity.rows; ++r) {
    const auto* d = disparity.ptr<float>(r);
    auto* z = depth.ptr<float>(r);
    for (int c = 0; c < disparity.cols; ++c) {
      if (d[c] <= 0) continue;
      const double depth_m = bf / d[c];
      if (max_depth_m <= 0 || depth_m <= max_depth_m) z[c] = static_cast<float>(depth_m);
    }
  }
  return depth;
}

}  // namespace pkslam::dense
