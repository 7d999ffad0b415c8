// Scale pyramid of a grey image, as ORB extraction and stereo SAD refinement use it.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace pkslam {

// Level 0 is the input image; level k is level k-1 resized (bilinear) to
// round(size0 / scale_factor^k). Because every cv::resize step maps pixel centres as
// x_src + 0.5 = (x_dst + 0.5) * src_size / dst_size, the chain composes exactly to
// x0 + 0.5 = (xk + 0.5) * size0 / size_k; ToBase/ToLevel use that exact map (per axis),
// not the nominal scale_factor^k (which is off by up to (s-1)/2 px, e.g. 1.3 px at level 7).
struct ImagePyramid {
  std::vector<cv::Mat> levels;  // CV_8UC1; levels[0] owns a copy of the input image

  int NumLevels() const { return static_cast<int>(levels.size()); }
  // Exact level-k -> level-0 scale per axis (size0 / size_k).
  double ScaleX(int level) const { return double(levels[0].cols) / levels[level].cols; }
  double ScaleY(int level) const { return double(levels[0].rows) / levels[level].rows; }

  // Level-k pixel coordinates -> level-0 pixel coordinates (pixel centres at integers).
  double ToBaseX(int level, double x) const { return (x + 0.5) * ScaleX(level) - 0.5; }
  double ToBaseY(int level, double y) const { return (y + 0.5) * ScaleY(level) - 0.5; }
  // Level-0 pixel coordinates -> level-k pixel coordinates.
  double ToLevelX(int level, double x) const { return (x + 0.5) / ScaleX(level) - 0.5; }
  double ToLevelY(int level, double y) const { return (y + 0.5) / ScaleY(level) - 0.5; }
};

// Size of level `level` for an image of `base` size (ORB-SLAM's rounding).
cv::Size PyramidLevelSize(cv::Size base, double scale_factor, int level);

// Builds (or rebuilds, reusing `pyramid`'s buffers when sizes match) the pyramid of a CV_8UC1
// image. `on_level_ready(k)`, if given, is called as soon as level k is complete so callers
// can start work on it while the smaller levels are still being resized.
template <typename OnLevelReady>
void BuildImagePyramid(const cv::Mat& image, double scale_factor, int n_levels,
                       ImagePyramid* pyramid, OnLevelReady&& on_level_ready);

void BuildImagePyramid(const cv::Mat& image, double scale_factor, int n_levels,
                       ImagePyramid* pyramid);

// ---------------------------------------------------------------------------------------------

namespace internal {
void ResizeLevel(const cv::Mat& src, cv::Size size, cv::Mat* dst);
void CheckPyramidInput(const cv::Mat& image, double scale_factor, int n_levels);
}  // namespace internal

template <typename OnLevelReady>
void BuildImagePyramid(const cv::Mat& image, double scale_factor, int n_levels,
                       ImagePyramid* pyramid, OnLevelReady&& on_level_ready) {
  internal::CheckPyramidInput(image, scale_factor, n_levels);
  pyramid->levels.resize(n_levels);
  image.copyTo(pyramid->levels[0]);
  on_level_ready(0);
  for (int level = 1; level < n_levels; ++level) {
    internal::ResizeLevel(pyramid->levels[level - 1],
                          PyramidLevelSize(image.size(), scale_factor, level),
                          &pyramid->levels[level]);
    on_level_ready(level);
  }
}

}  // namespace pkslam
