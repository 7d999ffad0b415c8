// Research baselines for keyframe studies (each behind ORB-SLAM3's shared safety exits):
//  interval       every N frames or T seconds
//  ptam           >= 20 frames since the last keyframe and moved more than a share of the
//                 median scene depth (PTAM's distance rule, scale-free)
//  match-count    fewer than 400 tracked points matched to the last keyframe (seed 002)
// (vins-parallax has its own file: vins_parallax_selector.h.)
#pragma once

#include "keyframe/keyframe_selector.h"

namespace pkslam {

struct BaselineOptions {
  int interval_frames = 10;              // interval: every this many frames (0: off)
  double interval_seconds = 0;           // interval: or every this many seconds (0: off)
  int ptam_min_frames = 20;              // ptam
  double ptam_min_distance_ratio = 0.1;  // ptam: distance / median depth of tracked points
  int match_count_min = 400;             // match-count
  double imu_uninitialised_interval_s = 0.25;

  void Check() const;
};

enum class BaselineKind { kInterval, kPtam, kMatchCount };

class BaselineSelector : public KeyframeSelector {
 public:
  BaselineSelector(BaselineKind kind, BaselineOptions options);
  std::string_view name() const override;
  bool NeedsTrackedPoints() const override { return kind_ != BaselineKind::kInterval; }
  SelectorDecision Decide(const SelectorInput& input) override;

 private:
  BaselineKind kind_;
  BaselineOptions options_;
};

}  // namespace pkslam
