// New map points from a new keyframe and its covisible neighbours (ORB-SLAM3's
// CreateNewMapPoints): keypoints without a point are matched between the pair (BoW, epipolar
// constraint) and triangulated (mapping/triangulation.h), then the accepted ones enter the map.
// Mapping thread. The search reads the map under the Atlas lock (shared) held by the caller;
// the points are added under the write lock, a parameter, which may be taken later.
#pragma once

#include <functional>
#include <vector>

#include "map_model/map_ids.h"
#include "mapping/triangulation.h"

namespace pkslam {

class Atlas;
class MapWriteLock;
class WorkMeter;

struct NeighbourTriangulationOptions {
  int neighbours = 10;     // best covisible keyframes searched
  bool monocular = false;  // baseline rule and triangulation tests (mapping/triangulation.h)
  // Asked before each neighbour after the first: true stops the search (a keyframe is queued).
  std::function<bool()> stop;
  WorkMeter* work = nullptr;  // counts a kTriangulationPair per pair searched (may be null)
};

// The triangulated matches of `keyframe`'s keypoints with its neighbours' (each keypoint of
// `keyframe` at most once, to its first accepted neighbour). Atlas lock held (shared).
std::vector<TriangulatedPoint> TriangulateWithNeighbours(
    const KeyFrame& keyframe, const NeighbourTriangulationOptions& options);

// Adds the points of `found` whose slots are still free in both keyframes (and whose neighbour
// was not retired meanwhile), observed by both. Returns them.
std::vector<MapPointPtr> AddTriangulatedPoints(const MapWriteLock& lock, Atlas* atlas,
                                               KeyFrame* keyframe,
                                               const std::vector<TriangulatedPoint>& found);

}  // namespace pkslam
