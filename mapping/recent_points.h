// The probation of new map points (ORB-SLAM3's MapPointCulling): points created for the last
// keyframes are watched until they have proved themselves (found where predicted, observed by
// enough keyframes) or are retired. Owned by the mapping thread; Cull changes the map under the
// Atlas's write lock, taken as a parameter.
#pragma once

#include <cstddef>
#include <vector>

#include "map_model/map_ids.h"

namespace pkslam {

class MapWriteLock;

struct RecentPointRule {
  // Retire a point found in fewer than this share of the frames that should have seen it.
  double min_found_ratio = 0.25;
  // Retire a point two keyframes old observed by no more than this many (stereo observations
  // count twice): 2 for monocular maps, 3 otherwise.
  int min_observations = 3;
};

class RecentPoints {
 public:
  void Watch(const MapPointPtr& point) { points_.push_back(point); }
  void Clear() { points_.clear(); }
  std::size_t size() const { return points_.size(); }

  // At keyframe `newest`: retires (SetBad) the watched points that failed the rule, stops
  // watching those retired meanwhile and those three keyframes old. Returns the number retired.
  int Cull(const MapWriteLock& lock, KeyFrameId newest, const RecentPointRule& rule);

 private:
  std::vector<MapPointPtr> points_;  // creation order
};

}  // namespace pkslam
