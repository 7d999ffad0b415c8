// How a camera pose and a velocity follow a whole map moved by x' = scale * rotation * x
// (new_from_old): local mapping applies it to every keyframe (ApplyScaledRotation) and tracking
// to a frame tracked before the move (InertialTracking::CarryAcross).
#pragma once

#include <Eigen/Core>

#include "core/geometry/se3.h"

namespace pkslam {

inline SE3d CameraFromMovedWorld(const SE3d& camera_from_world, const SO3d& new_from_old,
                                 double scale) {
  return SE3d(camera_from_world.so3() * new_from_old.Inverse(),
              scale * camera_from_world.translation());
}

inline Eigen::Vector3d VelocityInMovedWorld(const Eigen::Vector3d& velocity_world,
                                            const SO3d& new_from_old, double scale) {
  return scale * (new_from_old * velocity_world);
}

}  // namespace pkslam
