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
  PKSLAM_CHECK_OPTION(
      replay_world_from_camera.size() == replay_times_s.size() &&
          (replay_world_from_camera.empty() || replay_world_from_camera.size() >= 2),
      "replay", "{} poses, {} times", replay_world_from_camera.size(), replay_times_s.size());
  PKSLAM_CHECK_OPTION(replay_depth_min > 0 && replay_depth_min < replay_depth_max, "replay depth",
                      "[{}, {}]", replay_depth_min, replay_depth_max);
  PKSLAM_CHECK_OPTION(camera.fx > 0 && camera.fy > 0 && width > 0 && height > 0, "camera",
                      "fx {} fy {} {}x{}", camera.fx, camera.fy, width, height);
}

namespace {

// Points along random rays of random frames of a replayed path; all tracks kept.
SyntheticTracks SimulateReplay(const SyntheticTracksOptions& options) {
  std::mt19937_64 rng(options.seed);
  const std::size_t n = options.replay_world_from_camera.size();
  std::uniform_int_distribution<std::size_t> frame(0, n - 1);
  std::uniform_real_distribution<double> u(0, options.width), v(0, options.height);
  std::uniform_real_distribution<double> depth(options.replay_depth_min, options.replay_depth_max);
  std::normal_distribution<double> noise(0.0, options.noise_px > 0 ? options.noise_px : 1.0);
  SyntheticTracks out;
  for (const SE3d& p : options.replay_world_from_camera)
    out.camera_from_world.push_back(p.Inverse());
  const PinholeIntrinsics& k = options.camera;
  for (int i = 0; i < options.num_points; ++i) {
    const std::size_t f = frame(rng);
    const double d = depth(rng);
    const Eigen::Vector3d ray((u(rng) - k.cx) / k.fx, (v(rng) - k.cy) / k.fy, 1.0);
    out.points.push_back(options.replay_world_from_camera[f] * (d * ray));
  }
  out.tracks.camera = k;
  out.tracks.width = options.width;
  out.tracks.height = options.height;
  for (std::size_t f = 0; f < n; ++f) {
    for (std::size_t id = 0; id < out.points.size(); ++id) {
      const Eigen::Vector3d c = out.camera_from_world[f] * out.points[id];
      if (c.z() <= 0) continue;
      Eigen::Vector2d uv = k.Project(c);
      if (!(uv.x() >= 0 && uv.x() < options.width && uv.y() >= 0 && uv.y() < options.height)) {
        ++out.outside_projections;
        continue;
      }
      if (options.noise_px > 0) uv += Eigen::Vector2d(noise(rng), noise(rng));
      out.tracks.observations.push_back(
          {static_cast<int>(f), options.replay_times_s[f], static_cast<int>(id), uv.x(), uv.y()});
    }
  }
  return out;
}

}  // namespace

void ReplayPath(const Trajectory& world_from_body, const SE3d& body_from_camera, double fps,
                double start_s, double duration_s, SyntheticTracksOptions* options) {
  PKSLAM_CHECK_OPTION(fps > 0 && start_s >= 0 && duration_s >= 0, "replay",
                      "fps {} start {} "
                      "duration {}",
                      fps, start_s, duration_s);
  const auto& poses = world_from_body.poses;
  if (poses.size() < 2) throw Error("replay: the trajectory has fewer than two poses");
  options->replay_world_from_camera.clear();
  options->replay_times_s.clear();
  const std::int64_t begin = poses.front().t_ns + std::llround(start_s * 1e9);
  const std::int64_t end =
      duration_s > 0 ? begin + std::llround(duration_s * 1e9) : poses.back().t_ns + 1;
  const std::int64_t step = std::llround(1e9 / fps);
  std::size_t j = 0;
  for (std::int64_t t = begin; t < end; t += step) {
    while (j + 1 < poses.size() &&
           std::llabs(poses[j + 1].t_ns - t) <= std::llabs(poses[j].t_ns - t))
      ++j;
    if (std::llabs(poses[j].t_ns - t) > 10'000'000) continue;
    const double time_s = static_cast<double>(poses[j].t_ns) * 1e-9;
    if (!options->replay_times_s.empty() && time_s <= options->replay_times_s.back()) continue;
    options->replay_world_from_camera.push_back(poses[j].pose * body_from_camera);
    options->replay_times_s.push_back(time_s);
  }
  if (options->replay_world_from_camera.size() < 2) {
    throw Error("replay: fewer than two frames in the chosen window");
  }
}

SyntheticTracks SimulateTracks(const SyntheticTracksOptions& options) {
  options.Check();
  if (!options.replay_world_from_camera.empty()) return SimulateReplay(options);
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
