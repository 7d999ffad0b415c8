#include "core/features/image_pyramid.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/util/error.h"

namespace pkslam {

cv::Size PyramidLevelSize(cv::Size base, double scale_factor, int level) {
  const double inv_scale = 1.0 / std::pow(scale_factor, level);
  return {static_cast<int>(std::lround(base.width * inv_scale)),
          static_cast<int>(std::lround(base.height * inv_scale))};
}

void BuildImagePyramid(const cv::Mat& image, double scale_factor, int n_levels,
                       ImagePyramid* pyramid) {
  BuildImagePyramid(image, scale_factor, n_levels, pyramid, [](int) {});
}

namespace internal {

void ResizeLevel(const cv::Mat& src, cv::Size size, cv::Mat* dst) {
  cv::resize(src, *dst, size, 0, 0, cv::INTER_LINEAR);
}

void CheckPyramidInput(const cv::Mat& image, double scale_factor, int n_levels) {
  PKSLAM_CHECK(image.type() == CV_8UC1, "pyramid needs an 8-bit grey image, got type {}",
               image.type());
  PKSLAM_CHECK(scale_factor > 1.0, "scale factor {} must exceed 1", scale_factor);
  PKSLAM_CHECK(n_levels >= 1, "need at least one level, got {}", n_levels);
  const cv::Size top = PyramidLevelSize(image.size(), scale_factor, n_levels - 1);
  PKSLAM_CHECK(top.width >= 1 && top.height >= 1, "image {}x{} too small for {} levels", image.cols,
               image.rows, n_levels);
}

}  // namespace internal
}  // namespace pkslam
