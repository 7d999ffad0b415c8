#include "tracks/synthetic_tracks.h"

#include <cmath>
#include <numbers>
#include <random>

#include "core/util/error.h"

namespace pkslam {

void SyntheticTracksOptions::Check() const {
  PKSLAM_CHECK_OPTION(num_points > 0, "points", "{}", num_points);
  PKSLAM_CHECK_OPTION(x_min < x_max && z_min < z_max && z_min > 0, "point box",
                      "x [{}, {}], z [{}, {}]", x_min, x_max, z_min, z_max);
  PKSLAM_CHECK_OPTION(num_frames >= 2, "frames", "{}", num_frames);
  PKSLAM_CHECK_OPTION(fps > 0, "fps", "{}", fps);
  PKSLAM_CHECK_OPTION(shape == "line" || shape == "circle", "shape", "'{}' (line|circle)", shape);
  PKSLAM_CHECK_OPTION(step >= 0, "step", "{}", step);
  PKSLAM_CHECK_OPTION(noise_px >= 0, "noise", "{}", noise_px);
  PKSLAM_CHECK_OPTION(camera.fx > 0 && camera.fy > 0 && width > 0 && height > 0, "camera",
                      "fx {} fy {} {}x{}", camera.fx, camera.fy, width, height);
}

SyntheticTracks SimulateTracks(const SyntheticTracksOptions& options) {
  options.Check();
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> xy(options.x_min, options.x_max);
  std::uniform_real_distribution<double> z(options.z_min, options.z_max);
  std::normal_distribution<double> noise(0.0, options.noise_px > 0 ? options.noise_px : 1.0);

  SyntheticTracks out;
  // The camera looks along +z at the centre of the point box from z = 0.
  const double cx = 0.5 * (options.x_min + options.x_max);
  const int n = options.num_frames;
  for (int k = 0; k < n; ++k) {
    Eigen::Vector3d centre;
    double yaw = 0;
    if (options.shape == "line") {
      centre = {cx + options.step * (k - 0.5 * (n - 1)), cx, 0.0};
      yaw = 0.02 * std::sin(2 * std::numbers::pi * k / n);
    } else {
      const double radius = options.step * n / (2 * std::numbers::pi);
      const double a = 2 * std::numbers::pi * k / n;
      centre = {cx + radius * std::cos(a), cx + radius * std::sin(a), 0.0};
    }
    const SE3d world_from_camera(SO3d::Exp(Eigen::Vector3d(0, yaw, 0)), centre);
    out.camera_from_world.push_back(world_from_camera.Inverse());
  }
  auto project = [&](int frame, const Eigen::Vector3d& p, Eigen::Vector2d* uv) {
    const Eigen::Vector3d c = out.camera_from_world[static_cast<std::size_t>(frame)] * p;
    if (c.z() <= 0) return false;
    *uv = options.camera.Project(c);
    return uv->x() >= 0 && uv->x() < options.width && uv->y() >= 0 && uv->y() < options.height;
  };
  for (int i = 0; i < options.num_points; ++i) {
    const Eigen::Vector3d p(xy(rng), xy(rng), z(rng));
    Eigen::Vector2d uv;
    if (!project(0, p, &uv)) {
      ++out.dropped_points;
      continue;
    }
    out.points.push_back(p);
  }
  out.tracks.camera = options.camera;
  out.tracks.width = options.width;
  out.tracks.height = options.height;
  for (int k = 0; k < n; ++k) {
    for (std::size_t id = 0; id < out.points.size(); ++id) {
      Eigen::Vector2d uv;
      if (!project(k, out.points[id], &uv)) {
        ++out.outside_projections;
        continue;
      }
      if (options.noise_px > 0) uv += Eigen::Vector2d(noise(rng), noise(rng));
      out.tracks.observations.push_back({k, k / options.fps, static_cast<int>(id), uv.x(), uv.y()});
    }
  }
  return out;
}

}  // namespace pkslam
