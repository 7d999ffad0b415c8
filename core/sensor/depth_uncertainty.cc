#include "core/sensor/depth_uncertainty.h"

#include <cmath>
#include <cstdint>

#include "core/util/error.h"

namespace pkslam {
namespace {

// Metres at (x, y), or 0 for an invalid pixel (0, negative, NaN).
double DepthAt(const cv::Mat& depth, double scale, int x, int y) {
  const double d = depth.type() == CV_32F ? static_cast<double>(depth.at<float>(y, x))
                                          : static_cast<double>(depth.at<std::uint16_t>(y, x));
  return d > 0 && std::isfinite(d) ? d * scale : 0.0;
}

}  // namespace

DepthReading ReadKeypointDepth(const cv::Mat& depth, double scale, double x, double y,
                               double noise_k, double location_sigma_px, double bf) {
  PKSLAM_CHECK(depth.type() == CV_32F || depth.type() == CV_16U,
               "depth image type {} (want CV_16U or CV_32F)", depth.type());
  DepthReading r;
  const int xi = static_cast<int>(std::lround(x));
  const int yi = static_cast<int>(std::lround(y));
  if (xi < 0 || yi < 0 || xi >= depth.cols || yi >= depth.rows) return r;
  const double z = DepthAt(depth, scale, xi, yi);
  if (z <= 0) return r;
  // Central differences; the image border uses one-sided ones.
  const int x0 = std::max(xi - 1, 0);
  const int x1 = std::min(xi + 1, depth.cols - 1);
  const int y0 = std::max(yi - 1, 0);
  const int y1 = std::min(yi + 1, depth.rows - 1);
  const double zl = DepthAt(depth, scale, x0, yi);
  const double zr = DepthAt(depth, scale, x1, yi);
  const double zu = DepthAt(depth, scale, xi, y0);
  const double zd = DepthAt(depth, scale, xi, y1);
  if (zl <= 0 || zr <= 0 || zu <= 0 || zd <= 0) return r;  // next to a hole
  const double gx = x1 > x0 ? (zr - zl) / (x1 - x0) : 0.0;
  const double gy = y1 > y0 ? (zd - zu) / (y1 - y0) : 0.0;
  const double sensor = noise_k * z * z;
  const double location2 = location_sigma_px * location_sigma_px + 1.0 / 12.0;
  const double sigma = std::sqrt(sensor * sensor + (gx * gx + gy * gy) * location2);
  if (bf * sigma / (z * z) > kMaxDisparitySigmaPx) return r;  // a depth discontinuity
  r.depth = static_cast<float>(z);
  r.sigma = static_cast<float>(sigma);
  return r;
}

double DisparityInformation(double bf, double depth, double depth_sigma) {
  if (!(depth > 0) || !(depth_sigma > 0)) return 0.0;
  const double sigma_disparity = bf * depth_sigma / (depth * depth);
  return 1.0 / (sigma_disparity * sigma_disparity);
}

}  // namespace pkslam
