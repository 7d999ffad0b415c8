// Merging a global bundle adjustment back into a map that kept growing while it ran
// (ORB-SLAM3's RunGlobalBundleAdjustment write-back): keyframes and points of the problem get
// their optimised values; keyframes created meanwhile follow their spanning-tree parent
// (keeping their pose relative to it) and points created meanwhile follow their reference
// keyframe. Valid keyframe velocities (inertial maps) turn with their keyframe.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <map>

#include "map_model/estimation/bundle_collect.h"
#include "map_model/map_ids.h"

namespace pkslam {

class MapWriteLock;

// With the Atlas's write lock (a parameter). Keyframes and points no longer in `map` are left
// alone. Bumps the map's change index.
void MergeGlobalBundle(const MapWriteLock& lock, Map* map, const BundleProblem& problem,
                       const BundleResult& result);
// The same with the write-back of the problem's keyframes and points done by `apply` (e.g.
// ApplyInertialBundle); `apply_sets_velocities`: the problem's keyframes got their velocities
// from `apply` (only the others are turned with their keyframe).
void MergeGlobalBundle(const MapWriteLock& lock, Map* map, const BundleProblem& problem,
                       const std::function<void()>& apply, bool apply_sets_velocities);

// Gravity-preservation diagnostics (inertial maps, world z = gravity axis): the world's z axis
// seen from each live keyframe's camera (R_cw * e_z), and the largest angle (rad) by which a
// keyframe's view of it changed since `before`. Atlas mutex held.
std::map<KeyFrameId, Eigen::Vector3d> GravityInCameras(const Map& map);
double MaxTiltChange(const Map& map, const std::map<KeyFrameId, Eigen::Vector3d>& before);

}  // namespace pkslam
