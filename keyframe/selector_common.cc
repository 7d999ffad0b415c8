#include "keyframe/selector_common.h"

#include "keyframe/orbslam3_selector.h"

namespace pkslam {

std::optional<SelectorDecision> CommonSafetyExits(const SelectorInput& in,
                                                  double imu_uninitialised_interval_s) {
  if (IsInertial(in.sensor) && !in.imu_initialized) {
    SelectorDecision d;
    d.insert = in.SecondsSinceLastKeyFrame() >= imu_uninitialised_interval_s;
    d.reason = d.insert ? "imu-uninit-time" : "no";
    return d;
  }
  if (in.only_tracking) return SelectorDecision::No("only-tracking");
  if (in.local_mapping_stopped) return SelectorDecision::No("mapping-stopped");
  const int max_frames = static_cast<int>(in.fps + 0.5);
  if (in.frame_id < in.last_relocalisation_frame_id + max_frames &&
      in.keyframes_in_map > max_frames) {
    return SelectorDecision::No("after-reloc");
  }
  return std::nullopt;
}

SelectorDecision DecideFromReasons(const SelectorInput& input, const ReasonList& reasons,
                                   SelectorTrace trace) {
  SelectorDecision d =
      reasons.empty() ? SelectorDecision::No("no") : AcceptIfMappingCanTakeIt(input, reasons.str());
  d.trace = std::move(trace);
  return d;
}

}  // namespace pkslam
