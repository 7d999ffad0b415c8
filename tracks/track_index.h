// The tracks of a TrackSet indexed for reconstruction: per frame its observations sorted by
// track, and the track ids mapped to dense indices (a pkslam run's tracks are map point ids,
// sparse and large). A value built once from the file; read-only afterwards.
#pragma once

#include <Eigen/Core>
#include <unordered_map>
#include <vector>

#include "io/track_file.h"

namespace pkslam {

struct IndexedObservation {
  int track = 0;  // dense track index
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
};

struct TrackIndex {
  std::vector<std::vector<IndexedObservation>> frames;  // per frame, sorted by track
  std::vector<double> times_s;                          // per frame (NaN: no observation)
  std::vector<int> track_ids;                           // dense index -> id in the file
  std::unordered_map<int, int> dense_of_id;

  int num_frames() const { return static_cast<int>(frames.size()); }
  int num_tracks() const { return static_cast<int>(track_ids.size()); }
};

TrackIndex IndexTracks(const TrackSet& tracks);

// The observation of `track` in `frame` (nullptr when the frame does not see it).
const IndexedObservation* FindObservation(const std::vector<IndexedObservation>& frame, int track);

}  // namespace pkslam
