// Keyframe culling in inertial maps (ORB-SLAM3's LocalMapping::KeyFrameCulling, IMU branch).
//
// A redundant keyframe (its close points seen elsewhere, see KeyFrameSteps::CullKeyFrames) of an
// inertial map is retired only if the temporal chain stays dense enough for the IMU factors:
// its neighbours in the chain must be less than `max_gap_recent_s` apart, or, for keyframes
// older than the newest `window` of the chain once the IMU is initialised, less than
// `max_gap_old_s`. Before the last visual-inertial refinement (VIBA2) a keyframe that has not
// moved (`still_distance` from its predecessor) may also go within `max_gap_old_s`. Never the
// two newest keyframes, and nothing while the map holds no more than `window` keyframes.
// Retiring splices the keyframe out of the chain (InertialChain::SpliceOut): the next keyframe's
// preintegration absorbs its interval (re-integrated from the raw steps at the previous
// keyframe's bias).
//
// All functions run in the local mapping thread; they need the Atlas mutex (shared for the
// queries, exclusive for the splicing).
#pragma once

#include "map_model/map_ids.h"

namespace pkslam {
class MapWriteLock;
}  // namespace pkslam

namespace pkslam {

struct InertialCullingOptions {
  bool enabled = true;
  // Share of a keyframe's (close) points that must be seen by >= 3 other keyframes at the same
  // or a finer scale for it to be redundant: stereo/RGB-D-inertial (ORB-SLAM3 0.5), monocular.
  double redundancy_stereo = 0.5;
  double redundancy_mono = 0.9;
  // Newest keyframes of the chain that keep the tight spacing (ORB-SLAM3 Nd = 21).
  int window = 21;
  // Largest time between the neighbours of a culled keyframe: recent / older keyframes [s].
  double max_gap_recent_s = 0.5;
  double max_gap_old_s = 3.0;
  // A keyframe closer than this to its predecessor counts as still (map units).
  double still_distance = 0.02;

  void Check() const;
};

// What the time rules need to know about the map, taken once per culling round.
struct InertialCullingContext {
  KeyFrameId current_id = kInvalidId;
  KeyFrameId window_start_id = kInvalidId;  // oldest keyframe of the newest `window`
  int map_keyframes = 0;
  bool imu_initialized = false;
  bool refined = false;  // VIBA2 done
};

// Requires the Atlas mutex (shared).
InertialCullingContext MakeInertialCullingContext(const KeyFrame& current,
                                                  const InertialCullingOptions& options);

// Whether the chain allows retiring `candidate` (the rules above). Requires the Atlas mutex.
bool InertialCullingAllowed(const KeyFrame& candidate, const InertialCullingContext& context,
                            const InertialCullingOptions& options);

// Splices out retired keyframes still linked into the newest `length` keyframes of the chain
// ending at `newest` (a keyframe loop closing protected when it was culled is retired later).
// Returns how many (each through InertialChain::SpliceOut).
int RepairInertialChain(const MapWriteLock& lock, KeyFrame* newest, int length);

}  // namespace pkslam
