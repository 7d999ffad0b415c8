#include "tracking/keyframe_decision.h"

namespace pkslam {

bool MapStarving(const SelectorDecision& decision, const SelectorInput& in, int inliers,
                 const StarvingRule& rule) {
  if (decision.insert || in.local_mapping_idle || in.local_mapping_stopped || in.only_tracking ||
      in.local_mapping_queue >= 3) {
    return false;
  }
  if (decision.deferred_busy && inliers < rule.min_inliers) return true;
  return in.reference_tracked_points > 0 &&
         inliers < rule.min_reference_ratio * in.reference_tracked_points;
}

std::vector<std::string> CriteriaHeld(const SelectorDecision& decision) {
  std::vector<std::string> held;
  for (const auto& [key, value] : decision.trace) {
    if (key.starts_with("criterion") && value != 0) held.push_back(key);
  }
  return held;
}

const SelectorDecision& KeyFrameDecision::Decide(KeyframeSelector& selector,
                                                 const SelectorInput& in, int inliers,
                                                 const std::function<bool()>& queue_full,
                                                 bool* declined_queue_full) {
  last_ = selector.Decide(in);
  if (monocular_ && MapStarving(last_, in, inliers, rule_)) {
    last_.insert = true;
    last_.interrupt_local_ba = true;
    last_.reason += ";starving";
  }
  if (last_.insert && queue_full()) {
    // Backpressure: whatever the selector says, no keyframe while local mapping's queue is full.
    last_.insert = false;
    *declined_queue_full = true;
  }
  if (trace_enabled_) {
    trace_.push_back({in.t_ns, in.frame_id, last_, in.FramesSinceLastKeyFrame()});
  }
  return last_;
}

}  // namespace pkslam
