// Exact 2-D tracks of a simulated sequence (for `pkslam tracks export --simulated`, seed 002):
// `count` landmarks drawn uniformly by area on the scene's surfaces, projected into cam0 at
// every frame where they are in front, within `max_depth_m`, inside the image (the lens model
// with distortion decides) and not occluded (a ray to the landmark hits nothing nearer).
// The pixel stored is the ideal pinhole projection with cam0's true fx, fy, cx, cy: the
// undistorted keypoint a perfect detector would report. Written next to the sequence's other
// truth: DIR/truth/tracks_exact.txt (io/track_file.h), tracks_trajectory.txt (TUM,
// world_from_camera of cam0 at each frame), tracks_points.txt ("track x y z").
// Single-threaded; deterministic for a seed.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "core/camera/camera_model.h"
#include "core/geometry/se3.h"
#include "io/track_file.h"
#include "io/trajectory.h"
#include "sim/scene.h"

namespace pkslam::sim {

struct LandmarkTracksOptions {
  int count = 20000;
  double max_depth_m = 8.0;
  std::uint64_t seed = 1;

  void Check() const;
};

class LandmarkTracks {
 public:
  LandmarkTracks(const Scene& scene, const CameraModel& camera,
                 const LandmarkTracksOptions& options);

  // Frame `frame` (consecutive from 0) seen from cam0 at world_from_camera, stamped t_ns.
  void AddFrame(int frame, std::int64_t t_ns, const SE3d& world_from_camera);
  // Writes the three files into dir (created). Throws OutputError.
  void Write(const std::filesystem::path& dir) const;

  const TrackSet& tracks() const { return tracks_; }
  const std::vector<Eigen::Vector3d>& landmarks() const { return landmarks_; }

 private:
  const Scene& scene_;
  CameraModel camera_;
  LandmarkTracksOptions options_;
  std::vector<Eigen::Vector3d> landmarks_;
  std::vector<Eigen::Vector3d> normals_;
  TrackSet tracks_;
  Trajectory trajectory_;
};

}  // namespace pkslam::sim
