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
#include "tracks/track_file.h"

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

}  // namespace pkslam
