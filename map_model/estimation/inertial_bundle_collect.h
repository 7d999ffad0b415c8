// The map side of visual-inertial bundle adjustment (estimators/inertial/inertial_bundle.h):
// Collect (shared Atlas lock) builds the problem from the map's temporal keyframe chain
// (KeyFrame::imu.previous()), Apply (exclusive lock, through the map editor) writes the result
// back; the solve in between holds no lock.
#pragma once

#include <vector>

#include "estimators/inertial/inertial_bundle.h"
#include "map_model/estimation/bundle_collect.h"
#include "map_model/inertial_chain.h"
#include "map_model/keyframe_inertial.h"

namespace pkslam {

class MapWriteLock;

// Requires the Atlas mutex (shared). Keyframes without a valid inertial state end the chain.
InertialBundleProblem CollectLocalInertialBundle(KeyFrame* keyframe,
                                                 const InertialBundleOptions& options);
// free_tilt: the first chain keyframe is held by PositionYawPrior(gauge_information) instead of
// being fixed, and keyframes off the chain are free.
InertialBundleProblem CollectFullInertialBundle(KeyFrame* newest,
                                                const InertialBundleOptions& options,
                                                bool free_tilt = false,
                                                double gauge_information = 1e8);
// With the Atlas's write lock (a parameter): ApplyBundle for the visual part, then velocities and
// biases of free inertial keyframes, and re-linearises the preintegrations whose bias moved;
// stores result.next_prior on its keyframe if the map did not move map-wide since Collect.
// `map` is the map the problem was collected from.
void ApplyInertialBundle(const MapWriteLock& lock, Map* map, const InertialBundleProblem& problem,
                         const InertialBundleResult& result);

// Keyframes created from frames tracked before the IMU initialisation reached tracking have no
// estimated state yet: walking back from `newest` over those without one, each (oldest first)
// starts from its predecessor's state. Returns how many got one.
int StartMissingInertialStates(const MapWriteLock& lock, KeyFrame* newest);

// A full inertial BA of `newest`'s chain written back (an IMU initialisation stage's): the
// problem's values (ApplyInertialBundle), keyframes newer than `newest` take the estimated
// (shared) bias, a world change is recorded for tracking, and the map's change index moves,
// since every state moved (the local BA's marginalisation priors become stale).
void ApplyFullInertialBundle(const MapWriteLock& lock, Map* map, const KeyFrame& newest,
                             const InertialBundleProblem& problem,
                             const InertialBundleResult& result);

}  // namespace pkslam
