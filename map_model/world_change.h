// A change another thread made to a whole map that tracking must follow (local mapping's IMU
// initialisation and refinements, gravity refinement, full inertial BA; loop closing's 4-DoF
// corrections and merges). The map keeps them in an append-only log (Map::RecordWorldChange);
// tracking reads the entries past its cursor under the Atlas lock and applies each once
// (tracking/tracker_inertial.cc).
#pragma once

#include "core/geometry/so3.h"

namespace pkslam {

struct WorldChange {
  enum class Kind {
    kInertialState,  // keyframe states (velocities, biases, poses) re-estimated in place
    kTransform,      // the whole map moved: x' = scale * rotation * x (and states re-estimated)
  };
  Kind kind = Kind::kInertialState;
  SO3d rotation;       // kTransform: new_from_old
  double scale = 1.0;  // kTransform
};

}  // namespace pkslam
