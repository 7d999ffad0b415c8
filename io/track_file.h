// Tracks of 2-D projections (issue 24, seed 002): the text format `pkslam tracks` reads and
// writes. One observation per line after a header and the camera:
//
//   # pkslam tracks v1
//   camera FX FY CX CY WIDTH HEIGHT
//   # frame time_s track u v
//   0 0.000000000 17 512.31 311.94
//
// Frames are non-negative and non-decreasing down the file, times increase with the frame
// (equal within a frame), a track appears at most once per frame, and u, v are pixels of the
// undistorted image. '#' lines and blank lines are comments.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/geometry/pinhole_intrinsics.h"

namespace pkslam {

struct TrackObservation {
  int frame = 0;
  double t_s = 0;
  int track = 0;
  double u = 0, v = 0;
};

struct TrackSet {
  PinholeIntrinsics camera;
  int width = 0, height = 0;
  std::vector<TrackObservation> observations;  // in file order: by frame

  int NumFrames() const { return observations.empty() ? 0 : observations.back().frame + 1; }
};

// The 3-D points of tracks ("track x y z" rows, '#' comments): the truth beside a tracks
// file. The reader refuses a track listed twice (InputError with file and line); the writer is
// atomic, `comment` is its first line.
using TrackPoints = std::vector<std::pair<int, Eigen::Vector3d>>;
TrackPoints ReadTrackPoints(const std::filesystem::path& file);
void WriteTrackPoints(const TrackPoints& points, const std::filesystem::path& file,
                      const std::string& comment = "track x y z");

// Throws InputError naming the file and line.
TrackSet ReadTrackFile(const std::filesystem::path& file);
// Atomic write; throws OutputError. Observations must satisfy the rules above (checked).
void WriteTrackFile(const TrackSet& tracks, const std::filesystem::path& file);

}  // namespace pkslam
