#include "keyframe/orbslam3_selector.h"

#include "core/util/error.h"
#include "keyframe/selector_common.h"

namespace pkslam {

void OrbSlam3SelectorOptions::Check() const {
  PKSLAM_CHECK_OPTION(min_frames >= 0, "Keyframe.min_frames", "{}", min_frames);
  PKSLAM_CHECK_OPTION(imu_uninitialised_interval_s > 0, "Keyframe.imu_uninitialised_interval", "{}",
                      imu_uninitialised_interval_s);
  PKSLAM_CHECK_OPTION(inertial_interval_s > 0, "Keyframe.inertial_interval", "{}",
                      inertial_interval_s);
  PKSLAM_CHECK_OPTION(close_tracked_max >= 0 && close_untracked_min >= 0, "Keyframe.close_points",
                      "{} / {}", close_tracked_max, close_untracked_min);
}

OrbSlam3Selector::OrbSlam3Selector(OrbSlam3SelectorOptions options) : options_(options) {
  options_.Check();
}

SelectorDecision AcceptIfMappingCanTakeIt(const SelectorInput& input, std::string reason) {
  SelectorDecision d;
  d.reason = std::move(reason);
  if (input.local_mapping_idle || input.local_mapping_initializing) {
    d.insert = true;
    return d;
  }
  d.interrupt_local_ba = true;
  if (!IsMonocular(input.sensor) && input.local_mapping_queue < 3) {
    d.insert = true;
  } else {
    d.reason += ";busy";
    d.deferred_busy = true;
  }
  return d;
}

SelectorDecision OrbSlam3Selector::Decide(const SelectorInput& in) {
  const Sensor s = in.sensor;
  const double since_kf = in.SecondsSinceLastKeyFrame();
  SelectorDecision no;
  no.reason = "no";

  if (auto exit = CommonSafetyExits(in, options_.imu_uninitialised_interval_s)) return *exit;
  if (in.local_mapping_initializing && options_.no_keyframe_while_imu_initialises) {
    return SelectorDecision::No("imu-initialising");
  }
  const int max_frames =
      options_.max_frames > 0 ? options_.max_frames : static_cast<int>(in.fps + 0.5);

  const bool need_close = in.tracked_close < options_.close_tracked_max &&
                          in.untracked_close > options_.close_untracked_min;

  double th_ref_ratio = in.keyframes_in_map < 2 ? 0.4 : 0.75;
  if (s == Sensor::kMonocular) th_ref_ratio = 0.9;
  if (s == Sensor::kMonocularInertial) th_ref_ratio = in.inliers > 350 ? 0.75 : 0.9;

  const int frames_since = in.FramesSinceLastKeyFrame();
  const double ref = in.reference_tracked_points;
  const bool c1a = frames_since >= max_frames;
  const bool c1b = frames_since >= options_.min_frames && in.local_mapping_idle;
  const bool c1c = !IsMonocular(s) && !IsInertial(s) && (in.inliers < ref * 0.25 || need_close);
  const bool c2 = (in.inliers < ref * th_ref_ratio || need_close) && in.inliers > 15;
  const bool c3 = IsInertial(s) && since_kf >= options_.inertial_interval_s;
  const bool c4 =
      s == Sensor::kMonocularInertial && ((in.inliers < 75 && in.inliers > 15) || in.recently_lost);

  SelectorTrace trace;  // per frame, so only when a trace is written
  if (in.trace_wanted) {
    trace["inliers"] = in.inliers;
    trace["reference_tracked"] = ref;
    trace["mapping_idle"] = in.local_mapping_idle ? 1 : 0;
    no.trace = trace;
  }
  if (!(((c1a || c1b || c1c) && c2) || c3 || c4)) return no;
  ReasonList reasons;
  reasons.Add(c1a, "c1a");
  reasons.Add(c1b, "c1b");
  reasons.Add(c1c, "c1c");
  reasons.Add(c2, "c2");
  reasons.Add(c3, "c3");
  reasons.Add(c4, "c4");
  reasons.Add(need_close, "close");
  return DecideFromReasons(in, reasons, std::move(trace));
}

}  // namespace pkslam
