// Local mapping's keyframe culling (ORB-SLAM3's LocalMapping::KeyFrameCulling): a covisible
// keyframe of the newest one is retired when most of its points are seen well enough by other
// keyframes. In inertial maps the temporal chain's spacing rules decide too
// (mapping/inertial_culling.h) and a retired keyframe is spliced out of the chain.
//
// Runs on the local-mapping thread with the Atlas's write lock (a parameter: the culling
// retires keyframes).
#pragma once

#include <atomic>

#include "mapping/inertial_culling.h"

namespace pkslam {

class KeyFrame;
class MapWriteLock;

struct KeyFrameRedundancy {
  // A point counts when at least `observers` other keyframes see it at the same or a finer
  // scale (octave <= its octave + 1); the keyframe is redundant when more than `share` of its
  // points count.
  double share = 0.9;
  int observers = 3;
  // Stereo and RGB-D: only points closer than `max_depth` (the rig's th_depth) are its points;
  // far ones are weakly constrained anyway. Monocular: every point (max_depth < 0).
  double max_depth = -1.0;
};

// Whether `candidate` is redundant by `rule`. Atlas mutex held (shared at least).
bool IsRedundant(const KeyFrame& candidate, const KeyFrameRedundancy& rule);

struct KeyFrameCullingInput {
  KeyFrameRedundancy redundancy;
  // Set for inertial maps: the chain's rules, applied before the redundancy test.
  const InertialCullingOptions* inertial = nullptr;
  // Set while tracking waits with a new keyframe: an inertial round stops after 20 candidates.
  const std::atomic<bool>* abort = nullptr;
};

// Retires the redundant covisible keyframes of `newest` (at most the 100 best covisibles,
// never the map's origin; a keyframe loop closing protects stays). Returns how many.
int CullRedundantKeyFrames(const MapWriteLock& lock, KeyFrame* newest,
                           const KeyFrameCullingInput& input);

}  // namespace pkslam
