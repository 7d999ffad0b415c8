// What `pkslam tracks reconstruct` writes and how it is judged against truth:
//   DIR/trajectory.txt     every tracked frame, TUM (world_from_camera; world = first camera)
//   DIR/keyframes.txt      the keyframes, TUM
//   DIR/map.ply            the map points (io/point_cloud.h)
//   DIR/frames.csv         per frame: tracked, keyframe + reason, observations, map matches,
//                          PnP inliers, mean / median reprojection error (px)
//   DIR/reprojection_errors.csv   frame,track,error_px of every mapped observation
//   DIR/stats.json         the run: options, initial pair, keyframes by reason, times, per-frame
//                          mean reprojection error, and the accuracy against truth when known
// Truth (TRACKS_DIR/truth_trajectory.txt, TUM world_from_camera; truth_points.txt, "track x y
// z" rows), when present: ATE after Sim(3) alignment (evaluation/, as `pkslam eval --align
// sim3`), and the map point error after a Sim(3) alignment of the map to the true points.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "evaluation/statistics.h"
#include "io/trajectory.h"
#include "tracks/reconstruction.h"

namespace pkslam {

struct TracksTruth {
  Trajectory trajectory;                            // world_from_camera
  std::unordered_map<int, Eigen::Vector3d> points;  // by track id (may be empty)
};

// Reads DIR/truth_trajectory.txt and (if present) DIR/truth_points.txt; nullopt when the
// trajectory file does not exist. Malformed files throw InputError naming file and line.
std::optional<TracksTruth> ReadTracksTruth(const std::filesystem::path& dir);

struct TracksAccuracy {
  std::size_t pairs = 0;
  double scale = 1;               // of the Sim(3) alignment
  ErrorStatistics ate_m;          // translation ATE after Sim(3), truth units
  ErrorStatistics map_error;      // point error after the map's own Sim(3), truth units
  double median_truth_depth = 0;  // median point depth in the truth's cameras (scale)
  std::vector<Eigen::Vector3d> aligned_positions;  // per estimate pose (for plots)
  Trajectory aligned;                              // the estimate in the truth's frame
};

// Throws InputError when fewer than three poses pair with the truth.
TracksAccuracy EvaluateTracksReconstruction(const TracksReconstruction& r, const TrackIndex& index,
                                            const TracksTruth& truth);

Trajectory TracksTrajectory(const TracksReconstruction& r, const TrackIndex& index,
                            bool keyframes_only);

struct TracksOutputOptions {
  std::vector<int> histogram_frames;  // recorded for the report
  const TracksReconstructionOptions* options = nullptr;
};

// Writes every file above into dir (created). Throws OutputError.
void WriteTracksReconstruction(const std::filesystem::path& dir, const TrackSet& tracks,
                               const TrackIndex& index, const TracksReconstruction& r,
                               const std::optional<TracksAccuracy>& accuracy,
                               const TracksOutputOptions& output);

}  // namespace pkslam
