// The map side of the gravity refinement (local mapping's full visual-inertial BA with the
// world's tilt free, run again each time the keyframes have turned enough for gravity to be
// better observed; when: mapping/inertial_mapping.h, the gauge:
// estimators/inertial/gravity_gauge.h): the problem collected from the temporal chain, and its
// result merged back into a map that kept growing while it was solved.
//
// Local mapping's thread: Collect under the Atlas lock (shared), Apply with the write lock (a
// parameter).
#pragma once

#include <optional>

#include "map_model/estimation/inertial_bundle_collect.h"
#include "map_model/map_ids.h"

namespace pkslam {

class MapWriteLock;

struct GravityRefinementRule {
  // The chain's tilt observability (TiltObservability) that makes a refinement due: at least
  // `min_observability`, and `step` more than at the map's last refinement.
  double min_observability = 0.1;
  double step = 0.1;
  int max_keyframes = 300;  // longer chains are skipped (the BA would take too long)
};

struct GravityRefinementProblem {
  InertialBundleProblem bundle;  // the full chain ending at the keyframe, tilt free
  double observability = 0;      // of the chain's orientations
  int change_index = 0;          // the map's, to tell whether it moved meanwhile
};

// The refinement at `keyframe`, or nullopt when it is not due (or the keyframe was retired).
std::optional<GravityRefinementProblem> CollectGravityRefinement(
    KeyFrame* keyframe, const GravityRefinementRule& rule, const InertialBundleOptions& options);

// Merges `result` into `map` (MergeGlobalBundle with ApplyInertialBundle), gives keyframes
// tracked meanwhile `keyframe`'s new bias, records the observability reached and a world
// change for tracking. The caller has checked that the map did not move meanwhile
// (change_index). Returns how far gravity moved (rad), seen from the problem's first keyframe.
double ApplyGravityRefinement(const MapWriteLock& lock, Map* map, const KeyFrame& keyframe,
                              const GravityRefinementProblem& problem,
                              const InertialBundleResult& result);

}  // namespace pkslam
