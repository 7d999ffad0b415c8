#include "tracks/track_index.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pkslam {

TrackIndex IndexTracks(const TrackSet& tracks) {
  TrackIndex index;
  const int n = tracks.NumFrames();
  index.frames.resize(static_cast<std::size_t>(n));
  index.times_s.assign(static_cast<std::size_t>(n), std::numeric_limits<double>::quiet_NaN());
  for (const TrackObservation& o : tracks.observations) {
    auto [it, inserted] = index.dense_of_id.try_emplace(o.track, index.num_tracks());
    if (inserted) index.track_ids.push_back(o.track);
    index.frames[static_cast<std::size_t>(o.frame)].push_back({it->second, {o.u, o.v}});
    index.times_s[static_cast<std::size_t>(o.frame)] = o.t_s;
  }
  for (auto& frame : index.frames) {
    std::sort(
        frame.begin(), frame.end(),
        [](const IndexedObservation& a, const IndexedObservation& b) { return a.track < b.track; });
  }
  return index;
}

const IndexedObservation* FindObservation(const std::vector<IndexedObservation>& frame, int track) {
  const auto it = std::lower_bound(frame.begin(), frame.end(), track,
                                   [](const IndexedObservation& o, int t) { return o.track < t; });
  return it != frame.end() && it->track == track ? &*it : nullptr;
}

}  // namespace pkslam
