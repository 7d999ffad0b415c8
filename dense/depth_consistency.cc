#include "dense/depth_consistency.h"

#include <cmath>

#include "core/util/error.h"

namespace pkslam::dense {

void ConsistencyOptions::Check() const {
  PKSLAM_CHECK_OPTION(tolerance_rel > 0 && tolerance_rel < 1, "--consistency", "{}", tolerance_rel);
  PKSLAM_CHECK_OPTION(min_views >= 1, "--min-views", "{}", min_views);
}

ConsistencyResult FilterByConsistency(const cv::Mat& depth, const SE3d& world_from_camera,
                                      const std::vector<DepthView>& neighbours, const cv::Mat& rays,
                                      const CameraModel& camera, int pixel_step,
                                      const ConsistencyOptions& options) {
  options.Check();
  PKSLAM_CHECK(depth.type() == CV_32FC1 && rays.type() == CV_32FC2 && depth.size() == rays.size(),
               "depth (CV_32FC1) and rays (CV_32FC2) of one size needed");
  PKSLAM_CHECK(pixel_step >= 1, "pixel_step {}", pixel_step);
  const int w = depth.cols, h = depth.rows;
  PKSLAM_CHECK(w == camera.width() && h == camera.height(), "depth {}x{} for a {}x{} camera", w, h,
               camera.width(), camera.height());
  struct Neighbour {
    const cv::Mat* depth;
    Eigen::Matrix3f rotation;  // camera_j_from_camera_i
    Eigen::Vector3f translation;
  };
  std::vector<Neighbour> views;
  for (const DepthView& v : neighbours) {
    PKSLAM_CHECK(
        v.depth != nullptr && v.depth->type() == CV_32FC1 && v.depth->size() == depth.size(),
        "neighbour depth map does not match");
    const SE3d j_from_i = v.camera_from_world * world_from_camera;
    views.push_back(
        {v.depth, j_from_i.RotationMatrix().cast<float>(), j_from_i.translation().cast<float>()});
  }
  const bool ideal = !camera.HasDistortion();
  const float fx = static_cast<float>(camera.fx()), fy = static_cast<float>(camera.fy());
  const float cx = static_cast<float>(camera.cx()), cy = static_cast<float>(camera.cy());
  const float tolerance = static_cast<float>(options.tolerance_rel);

  ConsistencyResult result;
  result.depth = cv::Mat(depth.size(), CV_32FC1, cv::Scalar(0));
  for (int r = 0; r < h; r += pixel_step) {
    const float* z_row = depth.ptr<float>(r);
    const auto* ray = rays.ptr<cv::Vec2f>(r);
    float* out = result.depth.ptr<float>(r);
    for (int c = 0; c < w; c += pixel_step) {
      const float z = z_row[c];
      if (!(z > 0) || std::isnan(ray[c][0])) continue;
      ++result.candidates;
      const Eigen::Vector3f p(ray[c][0] * z, ray[c][1] * z, z);
      int confirmations = 0;
      float ratio_sum = 1.0f;
      for (const Neighbour& n : views) {
        const Eigen::Vector3f q = n.rotation * p + n.translation;
        if (!(q.z() > 0)) continue;
        float u, v;
        if (ideal) {
          u = fx * q.x() / q.z() + cx;
          v = fy * q.y() / q.z() + cy;
        } else {
          const auto uv = camera.Project(q.cast<double>());
          if (!uv) continue;
          u = static_cast<float>(uv->x());
          v = static_cast<float>(uv->y());
        }
        const int ui = static_cast<int>(std::lround(u)), vi = static_cast<int>(std::lround(v));
        if (ui < 0 || vi < 0 || ui >= w || vi >= h) continue;
        const float zj = n.depth->ptr<float>(vi)[ui];
        if (!(zj > 0) || std::abs(zj - q.z()) > tolerance * q.z()) continue;
        ++confirmations;
        ratio_sum += zj / q.z();
      }
      if (confirmations + 1 < options.min_views) continue;
      out[c] = options.average ? z * ratio_sum / static_cast<float>(confirmations + 1) : z;
      ++result.kept;
    }
  }
  return result;
}

}  // namespace pkslam::dense
