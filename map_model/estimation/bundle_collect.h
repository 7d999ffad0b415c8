// The map side of bundle adjustment: Collect turns keyframes and points of a map into the
// estimator's BundleProblem value (estimators/optim/bundle_adjustment.h), Apply writes a
// BundleResult back. Objects are named by id in the problem; Apply looks them up in the map
// again and skips whatever was retired or moved to another map while the solver ran.
#pragma once

#include <unordered_map>

#include "estimators/optim/bundle_adjustment.h"
#include "map_model/map_editor.h"
#include "map_model/map_ids.h"

namespace pkslam {

// Keyframe -> index into a problem's keyframes. Only looked up, never iterated (determinism).
using BundleKeyFrameIndex = std::unordered_map<const KeyFrame*, int>;

// Adds `point` and its observations by the keyframes in `index` (in keyframe-id order) to
// `problem`; returns false (and adds nothing) when none of them observes it. Shared by the
// visual and the inertial collectors. Requires the Atlas mutex (shared).
bool AddBundlePoint(const MapPointPtr& point, const BundleKeyFrameIndex& index,
                    BundleProblem* problem);

// Local BA around `keyframe`: it and its covisibles are optimised, their points too, and
// other keyframes observing those points are fixed.
BundleProblem CollectLocalBundle(const MapLock& lock, KeyFrame* keyframe,
                                 const BundleAdjustmentOptions& options);
// Global BA over every live keyframe and point of `map`; the map's first keyframe is fixed.
BundleProblem CollectGlobalBundle(const MapLock& lock, const Map& map);

// `map` is the map the problem was collected from (checked). Erases outlier observations (both
// directions), writes poses and positions of keyframes/points that are still live in `map`,
// updates normals and depth ranges of the points.
void ApplyBundle(const MapWriteLock& lock, Map* map, const BundleProblem& problem,
                 const BundleResult& result);

}  // namespace pkslam
