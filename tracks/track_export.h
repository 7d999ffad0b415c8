// `pkslam tracks export`: tracks from the two other places pkslam has them, so the
// reconstruction runs on the same scenes as the SLAM system (issue 24).
//   simulated  a sequence rendered with `pkslam simulate --tracks N`: its landmarks' exact
//              projections in cam0 (sim/landmark_tracks.h) with the generator's noise model
//              (Gaussian, sigma per coordinate), optionally every N-th frame of a time window;
//              the truth is the sequence's exact cam0 poses and landmark positions.
//   run        the keyframe observations of a pkslam run (RUN/sparse_model.txt): one frame per
//              keyframe, one track per map point, the keypoints' undistorted pixels; or, with
//              every_frame, every tracked frame's matched map points (RUN/frame_tracks.txt,
//              written by `pkslam run --frame-tracks`). The truth (optional) is cam0's pose at
//              each frame from the dataset's ground truth.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <utility>
#include <vector>

#include "io/track_file.h"
#include "io/trajectory.h"

namespace pkslam {

struct ExportedTracks {
  TrackSet tracks;
  Trajectory truth;          // world_from_camera per frame (empty: no truth)
  TrackPoints truth_points;  // (track, position)
};

struct SimulatedTracksExportOptions {
  double noise_px = 1.0;
  std::uint64_t seed = 1;
  int every = 1;          // keep every N-th frame
  double start_s = 0;     // from this many seconds after the first frame
  double duration_s = 0;  // for this long (0: to the end)

  void Check() const;
};

// Throws InputError naming the missing file (a sequence simulated without --tracks).
ExportedTracks ExportSimulatedTracks(const std::filesystem::path& sequence,
                                     const SimulatedTracksExportOptions& options);

// dataset may be empty (no truth). Throws InputError for a run without sparse_model.txt (or,
// with every_frame, without frame_tracks.txt).
ExportedTracks ExportRunTracks(const std::filesystem::path& run,
                               const std::filesystem::path& dataset, bool every_frame = false);

// OUT/tracks.txt, and truth_trajectory.txt + truth_points.txt when known.
void WriteExportedTracks(const ExportedTracks& exported, const std::filesystem::path& out);

}  // namespace pkslam
