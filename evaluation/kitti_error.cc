#include "evaluation/kitti_error.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/util/error.h"

namespace pkslam {

void KittiErrorOptions::Check() const {
  if (lengths_m.empty()) throw OptionError("KITTI errors need segment lengths");
  for (const double l : lengths_m) {
    if (!(l > 0) || !std::isfinite(l)) {
      throw OptionError(fmt::format("KITTI segment length {} m: must be positive", l));
    }
  }
  if (step_frames < 1) throw OptionError(fmt::format("KITTI step {}: must be >= 1", step_frames));
}

KittiErrors ComputeKittiErrors(const std::vector<SE3d>& ref, const std::vector<SE3d>& est,
                               const KittiErrorOptions& options) {
  options.Check();
  PKSLAM_CHECK(ref.size() == est.size(), "KITTI errors need associated poses ({} vs {})",
               ref.size(), est.size());
  std::vector<double> distance(ref.size(), 0.0);
  for (std::size_t k = 1; k < ref.size(); ++k) {
    distance[k] = distance[k - 1] + (ref[k].translation() - ref[k - 1].translation()).norm();
  }
  KittiErrors out;
  const auto step = static_cast<std::size_t>(options.step_frames);
  for (std::size_t first = 0; first < ref.size(); first += step) {
    for (const double length : options.lengths_m) {
      // The first frame past the length (strictly greater, as the devkit compares).
      const auto it = std::upper_bound(distance.begin() + static_cast<std::ptrdiff_t>(first),
                                       distance.end(), distance[first] + length);
      if (it == distance.end()) continue;
      const auto last = static_cast<std::size_t>(it - distance.begin());
      const SE3d delta_ref = ref[first].Inverse() * ref[last];
      const SE3d delta_est = est[first].Inverse() * est[last];
      const SE3d error = delta_est.Inverse() * delta_ref;
      const Eigen::Matrix3d r = error.so3().Matrix();
      const double cosine = std::clamp(0.5 * (r.trace() - 1.0), -1.0, 1.0);
      out.segments.push_back(
          {first, last, length, error.translation().norm() / length, std::acos(cosine) / length});
    }
  }
  constexpr double kRadToDeg = 180.0 / M_PI;
  double t_sum = 0, r_sum = 0;
  for (const auto& s : out.segments) {
    t_sum += s.translation_per_m;
    r_sum += s.rotation_rad_per_m;
  }
  if (!out.segments.empty()) {
    const double n = static_cast<double>(out.segments.size());
    out.translation_percent = 100.0 * t_sum / n;
    out.rotation_deg_per_100m = 100.0 * kRadToDeg * r_sum / n;
  }
  for (const double length : options.lengths_m) {
    KittiErrors::PerLength p;
    p.length_m = length;
    double t = 0, r = 0;
    for (const auto& s : out.segments) {
      if (s.length_m != length) continue;
      ++p.segments;
      t += s.translation_per_m;
      r += s.rotation_rad_per_m;
    }
    if (p.segments == 0) continue;
    p.translation_percent = 100.0 * t / static_cast<double>(p.segments);
    p.rotation_deg_per_100m = 100.0 * kRadToDeg * r / static_cast<double>(p.segments);
    out.per_length.push_back(p);
  }
  return out;
}

}  // namespace pkslam
