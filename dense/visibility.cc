#include "dense/visibility.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/util/error.h"

namespace pkslam::dense {
namespace {

struct Projected {
  float u, v, z;
  std::uint32_t index;
};

// Projects the points into one camera and marks the visible ones in `flags`.
void MarkVisible(const std::vector<Eigen::Vector3f>& points, const SE3d& camera_from_world,
                 const CameraModel& camera, const VisibilityOptions& o,
                 std::vector<Projected>* scratch, std::vector<float>* zbuffer,
                 std::vector<std::uint8_t>* flags) {
  const int w = camera.width(), h = camera.height();
  const Eigen::Matrix3f rotation = camera_from_world.RotationMatrix().cast<float>();
  const Eigen::Vector3f translation = camera_from_world.translation().cast<float>();
  const bool ideal = !camera.HasDistortion();
  const double fx = camera.fx(), fy = camera.fy(), cx = camera.cx(), cy = camera.cy();
  const double f = 0.5 * (fx + fy);
  // Occluders may be closer than min depth; anything beyond max depth + tolerance cannot
  // occlude a point within the range.
  const double far = o.max_depth_m + o.occlusion_tolerance_m;
  scratch->clear();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f pc = rotation * points[i] + translation;
    if (pc.z() < 0.05f || pc.z() > far) continue;
    double u, v;
    if (ideal) {
      u = fx * pc.x() / pc.z() + cx;
      v = fy * pc.y() / pc.z() + cy;
    } else {
      const auto uv = camera.Project(pc.cast<double>());
      if (!uv) continue;
      u = uv->x();
      v = uv->y();
    }
    const double margin = 0.5 * f * o.spacing_m / pc.z() + 1.0;
    if (u < -margin || v < -margin || u > w - 1 + margin || v > h - 1 + margin) continue;
    scratch->push_back(
        {static_cast<float>(u), static_cast<float>(v), pc.z(), static_cast<std::uint32_t>(i)});
  }
  zbuffer->assign(static_cast<std::size_t>(w) * h, std::numeric_limits<float>::infinity());
  for (const Projected& p : *scratch) {
    const double half = std::max(0.5, 0.5 * f * o.spacing_m / p.z);
    const int u0 = std::max(0, static_cast<int>(std::lround(p.u - half)));
    const int u1 = std::min(w - 1, static_cast<int>(std::lround(p.u + half)));
    const int v0 = std::max(0, static_cast<int>(std::lround(p.v - half)));
    const int v1 = std::min(h - 1, static_cast<int>(std::lround(p.v + half)));
    for (int v = v0; v <= v1; ++v) {
      float* row = zbuffer->data() + static_cast<std::size_t>(v) * w;
      for (int u = u0; u <= u1; ++u) row[u] = std::min(row[u], p.z);
    }
  }
  const double b = o.border_px;
  for (const Projected& p : *scratch) {
    if (p.z < o.min_depth_m || p.z > o.max_depth_m) continue;
    if (p.u < b - 0.5 || p.v < b - 0.5 || p.u >= w - 0.5 - b || p.v >= h - 0.5 - b) continue;
    const int u = static_cast<int>(std::lround(p.u)), v = static_cast<int>(std::lround(p.v));
    if (p.z <= (*zbuffer)[static_cast<std::size_t>(v) * w + u] + o.occlusion_tolerance_m) {
      (*flags)[p.index] = 1;
    }
  }
}

}  // namespace

void VisibilityOptions::Check() const {
  PKSLAM_CHECK_OPTION(min_depth_m >= 0 && max_depth_m > min_depth_m, "depth range", "[{}, {}]",
                      min_depth_m, max_depth_m);
  PKSLAM_CHECK_OPTION(border_px >= 0, "border_px", "{}", border_px);
  PKSLAM_CHECK_OPTION(spacing_m > 0, "spacing_m", "{}", spacing_m);
  PKSLAM_CHECK_OPTION(occlusion_tolerance_m >= 0, "occlusion_tolerance_m", "{}",
                      occlusion_tolerance_m);
}

std::vector<std::uint8_t> VisibleFromCameras(const std::vector<Eigen::Vector3f>& points,
                                             const std::vector<SE3d>& camera_from_world,
                                             const CameraModel& camera,
                                             const VisibilityOptions& options) {
  options.Check();
  PKSLAM_CHECK(points.size() < std::numeric_limits<std::uint32_t>::max(), "too many points");
  struct Local {
    std::vector<std::uint8_t> flags;
    std::vector<Projected> scratch;
    std::vector<float> zbuffer;
  };
  tbb::enumerable_thread_specific<Local> locals([&] {
    return Local{std::vector<std::uint8_t>(points.size(), 0), {}, {}};
  });
  tbb::parallel_for(std::size_t{0}, camera_from_world.size(), [&](std::size_t k) {
    Local& local = locals.local();
    MarkVisible(points, camera_from_world[k], camera, options, &local.scratch, &local.zbuffer,
                &local.flags);
  });
  std::vector<std::uint8_t> visible(points.size(), 0);
  for (const Local& local : locals) {
    for (std::size_t i = 0; i < points.size(); ++i) visible[i] |= local.flags[i];
  }
  return visible;
}

}  // namespace pkslam::dense
