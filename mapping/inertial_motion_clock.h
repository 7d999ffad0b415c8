// Local mapping's clocks of an inertial map's motion, read at each keyframe from the temporal
// chain (ORB-SLAM3's LocalMapping::Run IMU bookkeeping):
// - motion time: the seconds over which the body moved since the IMU initialisation, the clock
//   of the visual-inertial refinements when InertialMappingOptions::viba_motion_time is on;
// - ORB-SLAM3 v0.3's mTinit: the keyframe intervals over which the body travelled more than
//   5 cm in two steps; while it is under 10 s and the last two steps moved less than 10 cm, the
//   motion is too slow to refine the scale, and the keyframe selector is told so
//   (MappingBackend::TakeSlowMotionFlag).
// Owned by the mapping thread; Observe reads the chain under the Atlas lock (shared).
#pragma once

#include "map_model/map_ids.h"
#include "mapping/inertial_mapping.h"

namespace pkslam {

struct KeyFrameMotion {
  // The interval from the previous keyframe (capped at moving_max_interval_s) if the body moved
  // more than moving_distance or turned more than moving_angle_rad over it, else 0.
  double step_s = 0;
  // The slow-motion rule above held at this keyframe.
  bool slow_motion = false;
};

class InertialMotionClock {
 public:
  // The motion from `keyframe`'s chain predecessor to it. `refining`: the map's IMU is
  // initialised and its second refinement not yet done (only then does mTinit run). A keyframe
  // of another map than the last one's restarts the clocks.
  KeyFrameMotion Observe(const KeyFrame& keyframe, bool refining,
                         const InertialMappingOptions& options);
  // Adds a keyframe's step to the motion time; returns the motion time.
  double Advance(double step_s) { return moving_s_ += step_s; }
  // The IMU was (re-)initialised: both clocks start again.
  void Restart() {
    moving_s_ = 0;
    two_step_motion_s_ = 0;
  }
  double moving_s() const { return moving_s_; }
  double two_step_motion_s() const { return two_step_motion_s_; }

 private:
  const Map* map_ = nullptr;
  double moving_s_ = 0;
  double two_step_motion_s_ = 0;
};

}  // namespace pkslam
