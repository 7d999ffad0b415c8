#include "core/camera/camera_plausibility.h"

#include <fmt/format.h>

#include <cmath>

namespace pkslam {
namespace {

std::optional<ImplausibleParameter> Implausible(const char* parameter, std::string what) {
  return ImplausibleParameter{parameter, std::move(what)};
}

// The radial-tangential model over the image border: one to one, and not changing the corner
// radius by more than 4x either way.
std::optional<ImplausibleParameter> CheckDistortion(const CameraModel& camera) {
  const double w = camera.width() - 1.0;
  const double h = camera.height() - 1.0;
  const Eigen::Vector2d border[] = {{0, 0}, {w, 0}, {0, h}, {w, h},
                                    {w / 2, 0}, {w / 2, h}, {0, h / 2}, {w, h / 2}};
  for (const Eigen::Vector2d& uv : border) {
    const Eigen::Vector3d ray = camera.Unproject(uv);
    const auto back = ray.z() > 1e-6 ? camera.Project(ray) : std::nullopt;
    if (!back || (*back - uv).norm() > 0.5) {
      return Implausible("distortion", fmt::format(
                                           "the distortion does not map pixel ({:.0f}, {:.0f}) "
                                           "one to one (undistorted and distorted again it "
                                           "moves {} px): the coefficients cannot be a lens",
                                           uv.x(), uv.y(),
                                           back ? fmt::format("{:.1f}", (*back - uv).norm())
                                                : std::string("out of view")));
    }
    const double r_distorted = std::hypot((uv.x() - camera.cx()) / camera.fx(),
                                          (uv.y() - camera.cy()) / camera.fy());
    const double r_undistorted = std::hypot(ray.x() / ray.z(), ray.y() / ray.z());
    if (r_distorted < 0.05) continue;
    const double factor = r_undistorted / r_distorted;
    if (factor < 0.25 || factor > 4.0) {
      return Implausible(
          "distortion",
          fmt::format("the distortion moves pixel ({:.0f}, {:.0f}) {:.3f}x its distance from the "
                      "principal point (a real lens: well within 1/4 to 4x)",
                      uv.x(), uv.y(), factor));
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<ImplausibleParameter> FindImplausibleParameter(const CameraModel& camera) {
  const double w = camera.width();
  const double h = camera.height();
  for (const auto& [name, f] : {std::pair{"fx", camera.fx()}, std::pair{"fy", camera.fy()}}) {
    if (!(f >= 0.05 * w && f <= 6.0 * w)) {
      return Implausible(name, fmt::format("{} {} px is outside [{:.0f}, {:.0f}] (0.05 to 6 times "
                                           "the image width {}: fields of view of 170 to 9 deg)",
                                           name, f, 0.05 * w, 6.0 * w, camera.width()));
    }
  }
  const double aspect = camera.fy() / camera.fx();
  if (!(aspect >= 0.5 && aspect <= 2.0)) {
    return Implausible("fy", fmt::format("fy/fx = {:.3f} (fx {}, fy {}): pixels that far from "
                                         "square are a typo",
                                         aspect, camera.fx(), camera.fy()));
  }
  if (!(camera.cx() >= 0 && camera.cx() <= w)) {
    return Implausible("cx", fmt::format("cx {} px is outside the image (width {})", camera.cx(),
                                         camera.width()));
  }
  if (!(camera.cy() >= 0 && camera.cy() <= h)) {
    return Implausible("cy", fmt::format("cy {} px is outside the image (height {})", camera.cy(),
                                         camera.height()));
  }
  if (camera.type() == CameraType::kPinhole && camera.HasDistortion()) return CheckDistortion(camera);
  return std::nullopt;
}

}  // namespace pkslam
