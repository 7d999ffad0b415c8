#include "dense/depth_consistency.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "core/util/error.h"

namespace pkslam::dense {

void ConsistencyOptions::Check() const {
  PKSLAM_CHECK_OPTION(tolerance_rel > 0 && tolerance_rel < 1, "--consistency", "{}", tolerance_rel);
  PKSLAM_CHECK_OPTION(min_views >= 1, "--min-views", "{}", min_views);
  PKSLAM_CHECK_OPTION(max_depth_m >= 0, "max_depth_m", "{}", max_depth_m);
  PKSLAM_CHECK_OPTION(unconfirmed_max_depth_m >= 0, "--unconfirmed-max-depth", "{}",
                      unconfirmed_max_depth_m);
  PKSLAM_CHECK_OPTION(occluder_radius_px >= 0, "--occluder-radius", "{}", occluder_radius_px);
  PKSLAM_CHECK_OPTION(defer_ratio == 0 || defer_ratio >= 1, "--defer-ratio", "{} (0 or >= 1)",
                      defer_ratio);
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
    Eigen::Matrix3f back_rotation;  // camera_i_from_camera_j
    Eigen::Vector3f back_translation;
  };
  std::vector<Neighbour> views;
  for (const DepthView& v : neighbours) {
    PKSLAM_CHECK(
        v.depth != nullptr && v.depth->type() == CV_32FC1 && v.depth->size() == depth.size(),
        "neighbour depth map does not match");
    const SE3d j_from_i = v.camera_from_world * world_from_camera;
    const SE3d i_from_j = j_from_i.Inverse();
    views.push_back({v.depth, j_from_i.RotationMatrix().cast<float>(),
                     j_from_i.translation().cast<float>(), i_from_j.RotationMatrix().cast<float>(),
                     i_from_j.translation().cast<float>()});
  }
  const bool ideal = !camera.HasDistortion();
  const float fx = static_cast<float>(camera.fx()), fy = static_cast<float>(camera.fy());
  const float cx = static_cast<float>(camera.cx()), cy = static_cast<float>(camera.cy());
  const float tolerance = static_cast<float>(options.tolerance_rel);
  const float radius = static_cast<float>(options.occluder_radius_px);
  const float unconfirmed_max = static_cast<float>(options.unconfirmed_max_depth_m);
  const float own_max = options.max_depth_m > 0 ? static_cast<float>(options.max_depth_m)
                                                : std::numeric_limits<float>::infinity();
  const bool defer = options.defer_ratio > 0;
  const float defer_ratio = static_cast<float>(options.defer_ratio);
  // Pixel coordinates of a camera-frame point (nullopt behind the camera or unprojectable).
  auto project = [&](const Eigen::Vector3f& q) -> std::optional<Eigen::Vector2f> {
    if (!(q.z() > 0)) return std::nullopt;
    if (ideal) return Eigen::Vector2f(fx * q.x() / q.z() + cx, fy * q.y() / q.z() + cy);
    const auto uv = camera.Project(q.cast<double>());
    if (!uv) return std::nullopt;
    return uv->cast<float>();
  };

  ConsistencyResult result;
  result.depth = cv::Mat(depth.size(), CV_32FC1, cv::Scalar(0));
  result.views = cv::Mat(depth.size(), CV_8UC1, cv::Scalar(0));
  for (int r = 0; r < h; r += pixel_step) {
    const float* z_row = depth.ptr<float>(r);
    const auto* ray = rays.ptr<cv::Vec2f>(r);
    float* out = result.depth.ptr<float>(r);
    std::uint8_t* out_views = result.views.ptr<std::uint8_t>(r);
    for (int c = 0; c < w; c += pixel_step) {
      const float z = z_row[c];
      if (!(z > 0) || z > own_max || std::isnan(ray[c][0])) continue;
      ++result.candidates;
      const Eigen::Vector3f p(ray[c][0] * z, ray[c][1] * z, z);
      int confirmations = 0;
      int contradictions = 0;
      bool closer_view = false;
      float ratio_sum = 1.0f;  // weighted, the own estimate with weight 1
      float weight_sum = 1.0f;
      for (const Neighbour& n : views) {
        const Eigen::Vector3f q = n.rotation * p + n.translation;
        const auto uv = project(q);
        if (!uv) continue;
        const int ui = static_cast<int>(std::lround(uv->x()));
        const int vi = static_cast<int>(std::lround(uv->y()));
        if (ui < 0 || vi < 0 || ui >= w || vi >= h) continue;
        const float zj = n.depth->ptr<float>(vi)[ui];
        if (!(zj > 0)) continue;
        if (std::abs(zj - q.z()) <= tolerance * q.z()) {
          ++confirmations;
          // Inverse-variance weight of j's estimate z * zj / q.z relative to z: stereo depth
          // variance grows with depth^4, so var ~ (z / q.z)^2 zj^4 ~ z^2 zj^2 against z^4.
          const float w = (z * z) / (zj * zj);
          ratio_sum += w * zj / q.z();
          weight_sum += w;
          if (defer && zj * defer_ratio < z) closer_view = true;
        } else if (zj > q.z()) {
          ++contradictions;  // (a) j sees through p
        } else {
          // (b) j's surface in front of p: on i's ray, or a genuine occluder of p in j?
          const cv::Vec2f ray_j = rays.ptr<cv::Vec2f>(vi)[ui];
          if (std::isnan(ray_j[0])) continue;
          const Eigen::Vector3f s_i =
              n.back_rotation * Eigen::Vector3f(ray_j[0] * zj, ray_j[1] * zj, zj) +
              n.back_translation;
          const auto back = project(s_i);
          if (back && std::abs(back->x() - static_cast<float>(c)) <= radius &&
              std::abs(back->y() - static_cast<float>(r)) <= radius &&
              s_i.z() < (1.0f - tolerance) * z) {
            ++contradictions;
          }
        }
      }
      if (closer_view) {
        ++result.deferred;
        continue;
      }
      const bool vetoed = options.majority_veto && contradictions > confirmations;
      const bool confirmed = confirmations + 1 >= options.min_views;
      const bool unconfirmed_ok = options.keep_unconfirmed && contradictions == 0 &&
                                  (unconfirmed_max <= 0 || z <= unconfirmed_max);
      if (vetoed || !(confirmed || unconfirmed_ok)) {
        if (contradictions > 0) ++result.contradicted;
        continue;
      }
      if (confirmed) {
        out[c] = options.average ? z * ratio_sum / weight_sum : z;
        out_views[c] = static_cast<std::uint8_t>(std::min(confirmations + 1, 255));
      } else {
        out[c] = z;
        out_views[c] = 1;
        ++result.unconfirmed;
      }
      ++result.kept;
    }
  }
  return result;
}

}  // namespace pkslam::dense
