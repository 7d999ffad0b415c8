// How evenly keypoints cover an image: the share of grid cells holding at least one keypoint.
#pragma once

#include <algorithm>
#include <opencv2/core.hpp>
#include <vector>

namespace pkslam {

// Share (0..1) of the cells of a grid_cols x grid_rows grid laid over the image that contain
// at least one keypoint (e.g. 8 x 8 = 64 cells over the whole image).
inline double OccupiedGridShare(const std::vector<cv::KeyPoint>& keypoints, cv::Size image,
                                int grid_cols, int grid_rows) {
  std::vector<char> occupied(grid_cols * grid_rows, 0);
  for (const cv::KeyPoint& kp : keypoints) {
    const int c = std::clamp(static_cast<int>(kp.pt.x * grid_cols / image.width), 0, grid_cols - 1);
    const int r =
        std::clamp(static_cast<int>(kp.pt.y * grid_rows / image.height), 0, grid_rows - 1);
    occupied[r * grid_cols + c] = 1;
  }
  return double(std::count(occupied.begin(), occupied.end(), 1)) / occupied.size();
}

// Share of cell_px x cell_px pixel cells (e.g. 8 x 8 pixels; partial cells at the right and
// bottom edges count) that contain at least one keypoint.
inline double OccupiedPixelCellShare(const std::vector<cv::KeyPoint>& keypoints, cv::Size image,
                                     int cell_px) {
  const int cols = (image.width + cell_px - 1) / cell_px;
  const int rows = (image.height + cell_px - 1) / cell_px;
  std::vector<char> occupied(cols * rows, 0);
  for (const cv::KeyPoint& kp : keypoints) {
    const int c = std::clamp(static_cast<int>(kp.pt.x) / cell_px, 0, cols - 1);
    const int r = std::clamp(static_cast<int>(kp.pt.y) / cell_px, 0, rows - 1);
    occupied[r * cols + c] = 1;
  }
  return double(std::count(occupied.begin(), occupied.end(), 1)) / occupied.size();
}

}  // namespace pkslam
