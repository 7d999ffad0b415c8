#include "core/sensor/camera_rig.h"

#include <algorithm>
#include <limits>

namespace pkslam {

void CameraRig::UpdateDerived() {
  fx = camera.fx();
  fy = camera.fy();
  cx = camera.cx();
  cy = camera.cy();
  inv_fx = 1.0 / fx;
  inv_fy = 1.0 / fy;
  const double w = camera.width();
  const double h = camera.height();
  if (!camera.HasDistortion()) {
    bounds = {0.0, w, 0.0, h};
    return;
  }
  // ORB-SLAM undistorts the four corners; strongly distorted lenses bulge along the edges,
  // so sample the whole border and take the extremes.
  double min_x = std::numeric_limits<double>::max(), max_x = -min_x;
  double min_y = min_x, max_y = -min_x;
  constexpr int kSamples = 32;
  for (int i = 0; i <= kSamples; ++i) {
    const double t = static_cast<double>(i) / kSamples;
    for (const Eigen::Vector2d& uv : {Eigen::Vector2d(t * w, 0.0), Eigen::Vector2d(t * w, h),
                                      Eigen::Vector2d(0.0, t * h), Eigen::Vector2d(w, t * h)}) {
      const Eigen::Vector2d u = camera.UndistortPixel(uv);
      min_x = std::min(min_x, u.x());
      max_x = std::max(max_x, u.x());
      min_y = std::min(min_y, u.y());
      max_y = std::max(max_y, u.y());
    }
  }
  bounds = {min_x, max_x, min_y, max_y};
}

}  // namespace pkslam
