// Dense depth from a rectified stereo pair: OpenCV's semi-global block matching (SGBM) for the
// left and the right view, a left-right consistency check of our own (OpenCV's ximgproc is
// not available), a speckle filter, and depth = bf / disparity.
//
// The right view's disparity is computed by the same matcher on the mirrored pair: mirroring
// both images horizontally and swapping them turns "right pixel x matches left pixel x + d"
// into the left-view problem, and mirroring the result back gives d per right pixel.
#pragma once

#include <opencv2/core.hpp>

namespace pkslam::dense {

struct StereoDepthOptions {
  // Disparity search range [min_disparity, min_disparity + num_disparities), pixels; a
  // multiple of 16. 96 on EuRoC's 752x480 (bf ~ 48 px m) reaches down to 0.5 m.
  int min_disparity = 0;
  int num_disparities = 96;
  // Matching block side (odd, 3..11).
  int block_size = 5;
  // Smoothness penalties for disparity changes of 1 and of more than 1 pixel; 0 = OpenCV's
  // usual 8 * block_size^2 and 32 * block_size^2.
  int p1 = 0;
  int p2 = 0;
  // The best cost must beat the second best by this percentage.
  int uniqueness_ratio = 10;
  // Connected regions of fewer pixels than this whose disparity varies by at most
  // speckle_range pixels are removed as speckles (0 = no speckle filter).
  int speckle_window_size = 100;
  int speckle_range = 2;
  // Left-right check: |d_left(x) - d_right(x - d_left(x))| must not exceed this (pixels);
  // < 0 disables the check.
  double lr_max_difference = 1.0;
  // OpenCV's 3-way SGBM (8 directions' quality at 5-direction cost, multi-threaded).
  bool three_way = true;
  // OpenCV's SGBM leaves the first min_disparity + num_disparities columns invalid (their
  // search range leaves the image); padding both images on the left by that many black
  // columns lets a pixel at column c match any disparity <= c. The right view's matching (on
  // the mirrored pair) loses the same strip on the other side, which the left-right check
  // would then reject; padding recovers both (~25% of a 752-px EuRoC image at 96 disparities).
  bool pad_borders = true;

  void Check() const;
};

// Disparity of the left image (CV_32FC1, pixels; 0 = no valid disparity). Both images are
// 8-bit grey of the same size, rectified (a scene point lies on the same row in both).
// Throws Error on images of different sizes or types.
cv::Mat ComputeDisparity(const cv::Mat& rect_left, const cv::Mat& rect_right,
                         const StereoDepthOptions& options);

// The raw SGBM disparity of the left image without the left-right check (CV_32FC1, 0 = none).
cv::Mat ComputeRawDisparity(const cv::Mat& rect_left, const cv::Mat& rect_right,
                            const StereoDepthOptions& options);

// The raw disparity of the right image (right pixel x matches left pixel x + d), by the same
// matcher on the mirrored, swapped pair (CV_32FC1, 0 = none).
cv::Mat ComputeRightDisparity(const cv::Mat& rect_left, const cv::Mat& rect_right,
                              const StereoDepthOptions& options);

// Invalidates (sets to 0) left disparities that the right view's disparity does not confirm.
// Both maps CV_32FC1 as ComputeRawDisparity returns; returns the number of pixels removed.
// (OpenCV's SGBM also runs a cheaper one-sided check inside, from its own cost volume, which
// cannot be switched off; this one compares two independent matchings.)
int LeftRightCheck(const cv::Mat& right_disparity, double max_difference, cv::Mat* left_disparity);

// Depth in metres (CV_32FC1, 0 = none) from a disparity map: bf / d where d > 0 and the depth
// lies in (0, max_depth_m] (max_depth_m <= 0: no limit).
cv::Mat DisparityToDepth(const cv::Mat& disparity, double bf, double max_depth_m);

}  // namespace pkslam::dense
