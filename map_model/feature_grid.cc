#include "map_model/feature_grid.h"

#include <algorithm>
#include <cmath>

namespace pkslam {

FeatureGrid::FeatureGrid(const std::vector<cv::KeyPoint>& keypoints, const ImageBounds& bounds)
    : bounds_(bounds),
      inv_cell_width_(kCols / (bounds.max_x - bounds.min_x)),
      inv_cell_height_(kRows / (bounds.max_y - bounds.min_y)),
      cell_start_(kCols * kRows + 1, 0) {
  // Counting sort of keypoints into cells (two passes, one allocation).
  std::vector<std::int32_t> cell_of(keypoints.size(), -1);
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    int col = 0;
    int row = 0;
    if (CellOf(keypoints[i].pt, &col, &row)) {
      cell_of[i] = row * kCols + col;
      ++cell_start_[cell_of[i] + 1];
    }
  }
  for (int c = 0; c < kCols * kRows; ++c) cell_start_[c + 1] += cell_start_[c];
  indices_.resize(cell_start_.back());
  std::vector<std::int32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    if (cell_of[i] >= 0) indices_[fill[cell_of[i]]++] = static_cast<std::int32_t>(i);
  }
}

bool FeatureGrid::CellOf(const cv::Point2f& p, int* col, int* row) const {
  // Keypoints are undistorted and may fall slightly outside the bounds: those are dropped.
  *col = static_cast<int>(std::round((p.x - bounds_.min_x) * inv_cell_width_));
  *row = static_cast<int>(std::round((p.y - bounds_.min_y) * inv_cell_height_));
  return *col >= 0 && *col < kCols && *row >= 0 && *row < kRows;
}

std::vector<int> FeatureGrid::FeaturesInArea(const std::vector<cv::KeyPoint>& keypoints, double x,
                                             double y, double radius, int min_level,
                                             int max_level) const {
  std::vector<int> out;
  FeaturesInArea(keypoints, x, y, radius, min_level, max_level, &out);
  return out;
}

void FeatureGrid::FeaturesInArea(const std::vector<cv::KeyPoint>& keypoints, double x, double y,
                                 double radius, int min_level, int max_level,
                                 std::vector<int>* out) const {
  out->clear();
  if (cell_start_.empty()) return;
  const int min_col =
      std::max(0, static_cast<int>(std::floor((x - bounds_.min_x - radius) * inv_cell_width_)));
  const int max_col = std::min(
      kCols - 1, static_cast<int>(std::ceil((x - bounds_.min_x + radius) * inv_cell_width_)));
  const int min_row =
      std::max(0, static_cast<int>(std::floor((y - bounds_.min_y - radius) * inv_cell_height_)));
  const int max_row = std::min(
      kRows - 1, static_cast<int>(std::ceil((y - bounds_.min_y + radius) * inv_cell_height_)));
  if (min_col >= kCols || max_col < 0 || min_row >= kRows || max_row < 0) return;
  const bool check_levels = min_level > 0 || max_level >= 0;
  const float fx = static_cast<float>(x);
  const float fy = static_cast<float>(y);
  const float r = static_cast<float>(radius);
  for (int row = min_row; row <= max_row; ++row) {
    // Cells of one row are contiguous in indices_: scan them as one range.
    const std::int32_t begin = cell_start_[row * kCols + min_col];
    const std::int32_t end = cell_start_[row * kCols + max_col + 1];
    for (std::int32_t k = begin; k < end; ++k) {
      const std::int32_t i = indices_[k];
      const cv::KeyPoint& kp = keypoints[i];
      if (check_levels) {
        if (kp.octave < min_level) continue;
        if (max_level >= 0 && kp.octave > max_level) continue;
      }
      if (std::abs(kp.pt.x - fx) < r && std::abs(kp.pt.y - fy) < r) out->push_back(i);
    }
  }
}

}  // namespace pkslam
