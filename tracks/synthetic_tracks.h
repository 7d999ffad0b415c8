// The synthetic generator of seed 002 (`pkslam tracks simulate`): random 3-D points (its
// defaults: 200 points, x, y in [300, 800], z in [600, 1500], in the thesis's units), a camera
// trajectory, projection with K, Gaussian pixel noise; points whose projection misses the first
// frame are dropped (as the thesis does), later projections outside the image are left out and
// counted.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "core/geometry/se3.h"
#include "io/track_file.h"
#include "io/trajectory.h"

namespace pkslam {

struct SyntheticTracksOptions {
  int num_points = 200;
  double x_min = 300, x_max = 800;  // also y
  double z_min = 600, z_max = 1500;
  int num_frames = 60;
  double fps = 20;
  // "line": the camera slides sideways along x by `step` per frame, yawing slightly;
  // "circle": its centre circles in the x-y plane with radius `step` * num_frames / (2 pi).
  std::string shape = "line";
  double step = 5;
  double noise_px = 0;  // Gaussian sigma
  std::uint64_t seed = 1;
  PinholeIntrinsics camera{700, 700, 640, 360, 0};
  int width = 1280, height = 720;
  // A replayed path instead of the shape (e.g. EuRoC ground truth, see ReplayPath): one
  // world_from_camera per frame with its time. Points are then drawn along random rays of
  // random frames at a depth in [replay_depth_min, replay_depth_max] (the path's units), so
  // they lie where the camera looks; tracks start and end as the camera moves on, and no point
  // is dropped. num_frames and fps are ignored.
  std::vector<SE3d> replay_world_from_camera;
  std::vector<double> replay_times_s;
  double replay_depth_min = 1.0, replay_depth_max = 6.0;

  void Check() const;
};

struct SyntheticTracks {
  TrackSet tracks;
  std::vector<SE3d> camera_from_world;  // per frame
  std::vector<Eigen::Vector3d> points;  // per track id
  int dropped_points = 0;               // not seen in the first frame
  int outside_projections = 0;          // later projections outside the image (left out)
};

SyntheticTracks SimulateTracks(const SyntheticTracksOptions& options);

// The camera path of a ground-truth trajectory (world_from_body) resampled at `fps` (the
// nearest pose to each tick, within 10 ms) over [start_s, start_s + duration_s) from its
// first pose (duration 0: to the end), times body_from_camera. Sets the replay fields of
// *options. Throws Error when fewer than two frames result.
void ReplayPath(const Trajectory& world_from_body, const SE3d& body_from_camera, double fps,
                double start_s, double duration_s, SyntheticTracksOptions* options);

}  // namespace pkslam
