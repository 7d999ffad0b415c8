// Exits every selector shares with ORB-SLAM3: inertial maps need a keyframe every 0.25 s
// until the IMU is initialised, and no keyframe is taken in only-tracking mode, while local
// mapping is stopped (loop closure) or within fps frames after a relocalisation.
#pragma once

#include <optional>
#include <string>

#include "keyframe/keyframe_selector.h"

namespace pkslam {

// A decision when an exit applies, nullopt when the selector's own rule decides.
std::optional<SelectorDecision> CommonSafetyExits(const SelectorInput& input,
                                                  double imu_uninitialised_interval_s);

// The names of the rules that fired, joined by '+' in the order they are added ("camera+imu").
class ReasonList {
 public:
  void Add(bool fired, const char* name) {
    if (!fired) return;
    if (!text_.empty()) text_ += '+';
    text_ += name;
  }
  bool empty() const { return text_.empty(); }
  const std::string& str() const { return text_; }

 private:
  std::string text_;
};

// "no" when no rule fired, else the decision AcceptIfMappingCanTakeIt makes; with `trace`.
SelectorDecision DecideFromReasons(const SelectorInput& input, const ReasonList& reasons,
                                   SelectorTrace trace);

}  // namespace pkslam
