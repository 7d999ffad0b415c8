#include "rgbd/depth_cloud.h"

#include <limits>
#include <opencv2/imgproc.hpp>

#include "core/util/error.h"

namespace pkslam::rgbd {

void DepthFilterOptions::Check() const {
  PKSLAM_CHECK_OPTION(min_depth_m >= 0, "min_depth_m", "{}", min_depth_m);
  PKSLAM_CHECK_OPTION(max_depth_m == 0 || max_depth_m > min_depth_m, "max_depth_m", "{} vs min {}",
                      max_depth_m, min_depth_m);
  PKSLAM_CHECK_OPTION(bilateral_diameter >= 0, "bilateral_diameter", "{}", bilateral_diameter);
  PKSLAM_CHECK_OPTION(bilateral_sigma_depth_m > 0, "bilateral_sigma_depth_m", "{}",
                      bilateral_sigma_depth_m);
  PKSLAM_CHECK_OPTION(bilateral_sigma_space_px > 0, "bilateral_sigma_space_px", "{}",
                      bilateral_sigma_space_px);
}

cv::Mat PreprocessDepth(const cv::Mat& depth_m, const DepthFilterOptions& options) {
  options.Check();
  PKSLAM_CHECK(depth_m.type() == CV_32FC1, "depth must be CV_32FC1 metres, got type {}",
               depth_m.type());
  cv::Mat gated = depth_m.clone();
  const float lo = static_cast<float>(options.min_depth_m);
  const float hi = options.max_depth_m > 0 ? static_cast<float>(options.max_depth_m)
                                           : std::numeric_limits<float>::infinity();
  for (int v = 0; v < gated.rows; ++v) {
    float* row = gated.ptr<float>(v);
    for (int u = 0; u < gated.cols; ++u) {
      if (!(row[u] >= lo && row[u] <= hi)) row[u] = 0.0f;  // also NaN
    }
  }
  if (options.bilateral_diameter == 0) return gated;
  cv::Mat filtered;
  cv::bilateralFilter(gated, filtered, options.bilateral_diameter, options.bilateral_sigma_depth_m,
                      options.bilateral_sigma_space_px);
  // The range kernel gives invalid zeros negligible weight next to valid depths, but an
  // invalid pixel itself would take its valid neighbours' mean: keep it invalid.
  filtered.setTo(0.0f, gated == 0.0f);
  return filtered;
}

DepthLifter::DepthLifter(const CameraModel& camera)
    : camera_(camera), width_(camera.width()), height_(camera.height()) {
  rays_.resize(static_cast<std::size_t>(width_) * height_);
  for (int v = 0; v < height_; ++v) {
    for (int u = 0; u < width_; ++u) {
      Eigen::Vector2f ray;
      if (camera.HasDistortion()) {
        const Eigen::Vector3d b = camera.Unproject(Eigen::Vector2d(u, v));
        ray = Eigen::Vector2f(static_cast<float>(b.x() / b.z()), static_cast<float>(b.y() / b.z()));
      } else {
        ray = Eigen::Vector2f(static_cast<float>((u - camera.cx()) / camera.fx()),
                              static_cast<float>((v - camera.cy()) / camera.fy()));
      }
      rays_[static_cast<std::size_t>(v) * width_ + u] = ray;
    }
  }
}

Eigen::Vector3d DepthLifter::Lift(double u, double v, double d) const {
  if (!camera_.HasDistortion()) {
    return {(u - camera_.cx()) * d / camera_.fx(), (v - camera_.cy()) * d / camera_.fy(), d};
  }
  const Eigen::Vector3d b = camera_.Unproject(Eigen::Vector2d(u, v));
  return b * (d / b.z());
}

ColouredCloud LiftDepthImage(const cv::Mat& depth_m, const cv::Mat& colour_bgr,
                             const DepthLifter& lifter, int stride) {
  PKSLAM_CHECK(depth_m.type() == CV_32FC1 && depth_m.cols == lifter.width() &&
                   depth_m.rows == lifter.height(),
               "depth {}x{} type {} vs camera {}x{}", depth_m.cols, depth_m.rows, depth_m.type(),
               lifter.width(), lifter.height());
  PKSLAM_CHECK(
      colour_bgr.empty() || (colour_bgr.type() == CV_8UC3 && colour_bgr.size() == depth_m.size()),
      "colour image must be CV_8UC3 of the depth's size");
  PKSLAM_CHECK(stride >= 1, "stride {}", stride);
  ColouredCloud cloud;
  const std::size_t expected = static_cast<std::size_t>(depth_m.total()) / (stride * stride);
  cloud.points.reserve(expected);
  cloud.colours.reserve(expected);
  cloud.pixels.reserve(expected);
  for (int v = 0; v < depth_m.rows; v += stride) {
    const float* d = depth_m.ptr<float>(v);
    for (int u = 0; u < depth_m.cols; u += stride) {
      if (!(d[u] > 0)) continue;
      cloud.points.push_back(lifter.LiftPixel(u, v, d[u]));
      cloud.colours.push_back(colour_bgr.empty() ? cv::Vec3b(0, 0, 0)
                                                 : colour_bgr.at<cv::Vec3b>(v, u));
      cloud.pixels.push_back(v * depth_m.cols + u);
    }
  }
  return cloud;
}

}  // namespace pkslam::rgbd
