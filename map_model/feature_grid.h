// Uniform grid over the undistorted image for radius queries on keypoints (ORB-SLAM's
// 64x48 frame grid). Immutable after construction; safe to share between threads.
#pragma once

#include <cstdint>
#include <opencv2/core/types.hpp>
#include <vector>

#include "core/sensor/camera_rig.h"

namespace pkslam {

class FeatureGrid {
 public:
  static constexpr int kCols = 64;
  static constexpr int kRows = 48;

  FeatureGrid() = default;
  FeatureGrid(const std::vector<cv::KeyPoint>& keypoints, const ImageBounds& bounds);

  // Indices of keypoints with |x - kp.x| < radius and |y - kp.y| < radius and octave in
  // [min_level, max_level] (max_level < 0: no upper bound; min_level <= 0: no lower bound).
  std::vector<int> FeaturesInArea(const std::vector<cv::KeyPoint>& keypoints, double x, double y,
                                  double radius, int min_level = -1, int max_level = -1) const;
  // Same, into a caller-owned buffer (cleared first): no allocation in hot loops.
  void FeaturesInArea(const std::vector<cv::KeyPoint>& keypoints, double x, double y, double radius,
                      int min_level, int max_level, std::vector<int>* out) const;

 private:
  bool CellOf(const cv::Point2f& p, int* col, int* row) const;

  ImageBounds bounds_;
  double inv_cell_width_ = 0;
  double inv_cell_height_ = 0;
  // Compressed rows: keypoints of cell c are indices_[cell_start_[c] .. cell_start_[c + 1]),
  // cells in row-major order, keypoints ascending within a cell.
  std::vector<std::int32_t> cell_start_;
  std::vector<std::int32_t> indices_;
};

}  // namespace pkslam
