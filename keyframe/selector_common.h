// Exits every selector shares with ORB-SLAM3: inertial maps need a keyframe every 0.25 s
// until the IMU is initialised, and no keyframe is taken in only-tracking mode, while local
// mapping is stopped (loop closure) or within fps frames after a relocalisation.
#pragma once

#include <optional>

#include "keyframe/keyframe_selector.h"

namespace pkslam {

// A decision when an exit applies, nullopt when the selector's own rule decides.
std::optional<SelectorDecision> CommonSafetyExits(const SelectorInput& input,
                                                  double imu_uninitialised_interval_s);

}  // namespace pkslam
