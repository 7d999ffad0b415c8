// The map side of the IMU initialisation and its refinements (the solve is
// estimators/inertial/inertial_initializer.h): the keyframes a stage works on, collected from
// the temporal chain, and its result written back to every keyframe and point of the map.
//
// The keyframes a stage works on when tracking is ahead of local mapping (threaded runs). Keyframes
// tracking created after the one local mapping is processing are already in the map, linked by IMU,
// and wait in the queue; tracking predicts its next frames from the newest of them, so they need
// estimated states too. They join the initialisation (as in ORB-SLAM3, which takes the queued
// keyframes in first), and the few created while it is solved get their velocities by IMU
// prediction.
//
// Local mapping's thread, with the Atlas mutex held: shared to collect, exclusive (the lock a
// parameter) to apply and propagate.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/imu/imu_types.h"
#include "estimators/inertial/inertial_initializer.h"
#include "map_model/map_ids.h"

namespace pkslam {

class MapWriteLock;

// InertialChain::EndingAt(kf) (oldest first, ending at kf) continued forward over the keyframes
// linked after kf (`imu.next()`, same map, not retired, with a preintegration from their
// predecessor).
std::vector<KeyFrame*> InertialChainThrough(KeyFrame* kf);

// The keyframes linked after `last` that have no estimated state yet (stopping at the first
// that has one, or at a broken link) get velocities predicted along their preintegrations from
// `last`'s velocity, with `bias`, gravity `gravity_world` and metric = `scale` * map units (the
// world and units of `last`'s velocity; an IMU initialisation result before it is applied).
// The preintegrations must be linearised at `bias`. Returns how many keyframes were given one.
int PropagateVelocities(const MapWriteLock& lock, KeyFrame* last, const ImuBias& bias,
                        const Eigen::Vector3d& gravity_world, double scale);

// When a stage may run: the chain through the keyframe is long enough in keyframes and in time,
// and (monocular first stage) the camera travelled far enough for the scale to be observable.
struct InertialInitRule {
  int min_keyframes = 10;
  double min_time_s = 2.0;
  double min_travel = -1.0;  // map units; negative: no travel needed
};

// What a stage solves on, collected from the map.
struct InertialInitProblem {
  std::vector<KeyFrame*> chain;                 // InertialChainThrough(the keyframe), oldest first
  KeyFramePtr newest;                           // the chain's newest keyframe (shared)
  std::vector<InertialInitKeyFrame> keyframes;  // per chain keyframe: time and pose
  std::vector<PreintegratedImu> preintegrations;  // between consecutive chain keyframes
  ImuBias initial_bias;                           // the keyframe's current estimate
};

// The problem of a stage at `keyframe`, or nullopt when the rule does not hold yet (or the
// keyframe was retired). Atlas lock held (shared).
std::optional<InertialInitProblem> CollectInertialInit(KeyFrame* keyframe,
                                                       const InertialInitRule& rule);

// Writes a successful stage's result to `map`: the chain keyframes take their estimated
// velocities, every keyframe the bias (its preintegration re-integrated at it), keyframes
// tracking added after the chain predicted velocities (PropagateVelocities) and any other
// without a state the newest one's; then every keyframe and point is rotated into the gravity
// frame and scaled, the map marked initialised (at `t_ns` for the first stage, `refinement`
// false) and the transform recorded as a world change for tracking.
void ApplyInertialInit(const MapWriteLock& lock, Map* map, const InertialInitProblem& problem,
                       const InertialInitResult& result, bool refinement, std::int64_t t_ns);

// Rotates (world' = R * world) and scales (x' = s x) every keyframe (pose, velocity) and point
// of the map, as ORB-SLAM3's Map::ApplyScaledRotation.
void ApplyScaledRotation(const MapWriteLock& lock, Map* map, const SO3d& new_from_old,
                         double scale);

}  // namespace pkslam
