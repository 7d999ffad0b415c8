#include "keyframe/baseline_selectors.h"

#include <algorithm>
#include <vector>

#include "core/util/error.h"
#include "keyframe/selector_common.h"

namespace pkslam {

void BaselineOptions::Check() const {
  PKSLAM_CHECK_OPTION(interval_frames >= 0 && interval_seconds >= 0 &&
                          (interval_frames > 0 || interval_seconds > 0),
                      "Keyframe.frames/seconds", "{} / {}", interval_frames, interval_seconds);
  PKSLAM_CHECK_OPTION(ptam_min_frames >= 0 && ptam_min_distance_ratio >= 0, "Keyframe.ptam",
                      "{} / {}", ptam_min_frames, ptam_min_distance_ratio);
  PKSLAM_CHECK_OPTION(match_count_min > 0, "Keyframe.min_matches", "{}", match_count_min);
}

BaselineSelector::BaselineSelector(BaselineKind kind, BaselineOptions options)
    : kind_(kind), options_(options) {
  options_.Check();
}

std::string_view BaselineSelector::name() const {
  switch (kind_) {
    case BaselineKind::kInterval:
      return "interval";
    case BaselineKind::kPtam:
      return "ptam";
    case BaselineKind::kMatchCount:
      return "match-count";
  }
  return "?";
}

SelectorDecision BaselineSelector::Decide(const SelectorInput& in) {
  if (auto exit = CommonSafetyExits(in, options_.imu_uninitialised_interval_s)) return *exit;
  SelectorTrace trace;
  const int frames = in.FramesSinceLastKeyFrame();
  bool want = false;
  std::string reason;
  switch (kind_) {
    case BaselineKind::kInterval:
      want = (options_.interval_frames > 0 && frames >= options_.interval_frames) ||
             (options_.interval_seconds > 0 &&
              in.SecondsSinceLastKeyFrame() >= options_.interval_seconds);
      reason = "interval";
      break;
    case BaselineKind::kPtam: {
      std::vector<double> depths;
      for (const auto& p : in.points) {
        depths.push_back((in.camera_from_world * p.position_world).z());
      }
      double median = 0;
      if (!depths.empty()) {
        std::nth_element(depths.begin(), depths.begin() + static_cast<long>(depths.size() / 2),
                         depths.end());
        median = depths[depths.size() / 2];
      }
      const double moved = (in.camera_from_world.Inverse().translation() -
                            in.last_keyframe_camera_from_world.Inverse().translation())
                               .norm();
      trace["distance_ratio"] = median > 0 ? moved / median : 0.0;
      want = frames >= options_.ptam_min_frames && median > 0 &&
             moved > options_.ptam_min_distance_ratio * median;
      reason = "ptam";
      break;
    }
    case BaselineKind::kMatchCount: {
      const auto matched = std::count_if(in.points.begin(), in.points.end(),
                                         [](const SelectorPoint& p) { return p.in_last_keyframe; });
      trace["M_c"] = static_cast<double>(matched);
      want = matched < options_.match_count_min;
      reason = "matches";
      break;
    }
  }
  trace["A_c"] = static_cast<double>(in.points.size());
  ReasonList reasons;
  reasons.Add(want, reason.c_str());
  return DecideFromReasons(in, reasons, std::move(trace));
}

}  // namespace pkslam
