#include "core/frame/feature_grid.h"

#include <algorithm>
#include <cmath>

namespace pkslam {

FeatureGrid::FeatureGrid(const std::vector<cv::KeyPoint>& keypoints, const ImageBounds& bounds)
    : bounds_(bounds),
      inv_cell_width_(kCols / (bounds.max_x - bounds.min_x)),
      inv_cell_height_(kRows / (bounds.max_y - bounds.min_y)),
      cells_(kCols * kRows) {
  const std::size_t reserve = keypoints.size() / (kCols * kRows) + 2;
  for (auto& c : cells_) c.reserve(reserve);
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    int col = 0;
    int row = 0;
    if (CellOf(keypoints[i].pt, &col, &row)) {
      cells_[row * kCols + col].push_back(static_cast<std::int32_t>(i));
    }
  }
}

bool FeatureGrid::CellOf(const cv::Point2f& p, int* col, int* row) const {
  // Keypoints are undistorted and may fall slightly outside the bounds: those are dropped.
  *col = static_cast<int>(std::round((p.x - bounds_.min_x) * inv_cell_width_));
  *row = static_cast<int>(std::round((p.y - bounds_.min_y) * inv_cell_height_));
  return *col >= 0 && *col < kCols && *row >= 0 && *row < kRows;
}

std::vector<int> FeatureGrid::FeaturesInArea(const std::vector<cv::KeyPoint>& keypoints,
                                             double x, double y, double radius, int min_level,
                                             int max_level) const {
  std::vector<int> out;
  if (cells_.empty()) return out;
  const int min_col =
      std::max(0, static_cast<int>(std::floor((x - bounds_.min_x - radius) * inv_cell_width_)));
  const int max_col = std::min(
      kCols - 1, static_cast<int>(std::ceil((x - bounds_.min_x + radius) * inv_cell_width_)));
  const int min_row =
      std::max(0, static_cast<int>(std::floor((y - bounds_.min_y - radius) * inv_cell_height_)));
  const int max_row = std::min(
      kRows - 1, static_cast<int>(std::ceil((y - bounds_.min_y + radius) * inv_cell_height_)));
  if (min_col >= kCols || max_col < 0 || min_row >= kRows || max_row < 0) return out;
  const bool check_levels = min_level > 0 || max_level >= 0;
  for (int row = min_row; row <= max_row; ++row) {
    for (int col = min_col; col <= max_col; ++col) {
      for (const std::int32_t i : cells_[row * kCols + col]) {
        const cv::KeyPoint& kp = keypoints[i];
        if (check_levels) {
          if (kp.octave < min_level) continue;
          if (max_level >= 0 && kp.octave > max_level) continue;
        }
        if (std::abs(kp.pt.x - x) < radius && std::abs(kp.pt.y - y) < radius) out.push_back(i);
      }
    }
  }
  return out;
}

}  // namespace pkslam
