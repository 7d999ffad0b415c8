// The keyframes an IMU initialisation stage works on when tracking is ahead of local mapping
// (threaded runs). Keyframes tracking created after the one local mapping is processing are
// already in the map, linked by IMU, and wait in the queue; tracking predicts its next frames
// from the newest of them, so they need estimated states too. They join the initialisation
// (as in ORB-SLAM3, which takes the queued keyframes in first), and the few created while it
// is solved get their velocities by IMU prediction.
//
// Both run in the local mapping thread with the Atlas mutex held (shared for the chain,
// exclusive for the propagation).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/imu/imu_types.h"

namespace pkslam {

class KeyFrame;

// InertialChain::EndingAt(kf) (oldest first, ending at kf) continued forward over the keyframes
// linked after kf (`imu.next()`, same map, not retired, with a preintegration from their
// predecessor).
std::vector<KeyFrame*> InertialChainThrough(KeyFrame* kf);

// The keyframes linked after `last` that have no estimated state yet (stopping at the first
// that has one, or at a broken link) get velocities predicted along their preintegrations from
// `last`'s velocity, with `bias`, gravity `gravity_world` and metric = `scale` * map units (the
// world and units of `last`'s velocity; an IMU initialisation result before it is applied).
// The preintegrations must be linearised at `bias`. Returns how many keyframes were given one.
int PropagateVelocities(KeyFrame* last, const ImuBias& bias, const Eigen::Vector3d& gravity_world,
                        double scale);

}  // namespace pkslam
