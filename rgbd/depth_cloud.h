// Depth images to 3-D: the range gate and bilateral filter of seed 000 (section 4-3-3), and
// lifting pixels to camera-frame points rho(u, v, d) = ((u - cx) d / fx, (v - cy) d / fy, d)
// (seed 000 Eq. 3-14, seed 001 Eqs. 1-2), generalised to distorted cameras by per-pixel rays.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "core/camera/camera_model.h"

namespace pkslam::rgbd {

struct DepthFilterOptions {
  // Depths outside [min, max] are set to 0 (invalid): structured-light sensors are unreliable
  // closer than ~0.8 m and noisy beyond ~3 m (seed 000 keeps 0.8-3.0 m). max 0 = no limit.
  double min_depth_m = 0.8;
  double max_depth_m = 3.0;
  // cv::bilateralFilter on the metric depth: neighbourhood diameter in pixels (0 = no filter).
  int bilateral_diameter = 5;
  // Depth (range) sigma [m]: neighbours differing by several sigmas do not mix, so depth
  // edges and the zeros of invalid pixels (>= min_depth away) stay sharp.
  double bilateral_sigma_depth_m = 0.03;
  // Spatial sigma [px].
  double bilateral_sigma_space_px = 3.0;

  void Check() const;
};

// CV_32FC1 metres, 0 = invalid. Pixels invalid before filtering stay invalid after it.
cv::Mat PreprocessDepth(const cv::Mat& depth_m, const DepthFilterOptions& options);

// Back-projection through a camera model. Immutable; share freely between threads.
class DepthLifter {
 public:
  explicit DepthLifter(const CameraModel& camera);

  int width() const { return width_; }
  int height() const { return height_; }
  // The point at depth d (along the optical axis, z = d) seen by integer pixel (u, v).
  Eigen::Vector3f LiftPixel(int u, int v, float d) const {
    const Eigen::Vector2f& r = rays_[static_cast<std::size_t>(v) * width_ + u];
    return {r.x() * d, r.y() * d, d};
  }
  // The same for a sub-pixel position (keypoints); undistorts on the fly.
  Eigen::Vector3d Lift(double u, double v, double d) const;

 private:
  CameraModel camera_;
  int width_ = 0;
  int height_ = 0;
  std::vector<Eigen::Vector2f> rays_;  // (x/z, y/z) of every pixel, row-major
};

// A camera-frame point cloud with the colour and pixel of every point.
struct ColouredCloud {
  std::vector<Eigen::Vector3f> points;
  std::vector<cv::Vec3b> colours;  // BGR
  std::vector<int> pixels;         // v * width + u

  std::size_t size() const { return points.size(); }
};

// Every stride-th pixel (in u and v) with valid depth (> 0). colour_bgr may be empty (black).
ColouredCloud LiftDepthImage(const cv::Mat& depth_m, const cv::Mat& colour_bgr,
                             const DepthLifter& lifter, int stride = 1);

}  // namespace pkslam::rgbd
