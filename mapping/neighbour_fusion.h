// Duplicate points between a new keyframe and its neighbourhood are fused (ORB-SLAM3's
// SearchInNeighbors): the keyframe's points are projected into its covisible keyframes and
// their covisible keyframes, and theirs into it; a projection landing on a keypoint that
// already has a point merges the two (OrbMatcher::Fuse). Mapping thread, with the Atlas's
// write lock (a parameter).
#pragma once

#include <cstdint>

#include "map_model/map_ids.h"

namespace pkslam {

class MapWriteLock;
class WorkMeter;

struct NeighbourFusionOptions {
  int first_ring = 10;   // best covisible keyframes (ORB-SLAM3: 30 monocular, 10 otherwise)
  int second_ring = 20;  // best covisibles of each of those
  // Counts the point projections tried as kFuseProjection work (may be null).
  WorkMeter* work = nullptr;
};

// Fuses as above, then refreshes the descriptors, normals and depths of the keyframe's points
// and its covisibility links. Returns the number of keyframes fused with; 0 when the keyframe
// was retired or its map dropped meanwhile.
int FuseWithNeighbours(const MapWriteLock& lock, KeyFrame* keyframe,
                       const NeighbourFusionOptions& options);

}  // namespace pkslam
