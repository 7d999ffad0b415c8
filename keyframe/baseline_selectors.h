// Research baselines for keyframe studies (each behind ORB-SLAM3's shared safety exits):
//  interval       every N frames or T seconds
//  ptam           >= 20 frames since the last keyframe and moved more than a share of the
//                 median scene depth (PTAM's distance rule, scale-free)
//  match-count    fewer than 400 tracked points matched to the last keyframe (seed 002)
//  vins-parallax  mean pixel parallax to the last keyframe > 10 px, or < 50 tracked points
#pragma once

#include <unordered_map>

#include <Eigen/Core>

#include "keyframe/keyframe_selector.h"

namespace pkslam {

struct BaselineOptions {
  int interval_frames = 10;        // interval: every this many frames (0: off)
  double interval_seconds = 0;     // interval: or every this many seconds (0: off)
  int ptam_min_frames = 20;        // ptam
  double ptam_min_distance_ratio = 0.1;  // ptam: distance / median depth of tracked points
  int match_count_min = 400;       // match-count
  double vins_parallax_px = 10.0;  // vins-parallax
  int vins_min_tracked = 50;
  double imu_uninitialised_interval_s = 0.25;

  void Check() const;
};

enum class BaselineKind { kInterval, kPtam, kMatchCount, kVinsParallax };

class BaselineSelector : public KeyframeSelector {
 public:
  BaselineSelector(BaselineKind kind, BaselineOptions options);
  std::string_view name() const override;
  bool NeedsTrackedPoints() const override { return kind_ != BaselineKind::kInterval; }
  SelectorDecision Decide(const SelectorInput& input) override;
  void OnKeyFrameInserted(const SelectorInput& input) override;
  void Reset() override { keyframe_uv_.clear(); }

 private:
  BaselineKind kind_;
  BaselineOptions options_;
  std::unordered_map<MapPointId, Eigen::Vector2d> keyframe_uv_;  // vins-parallax
};

}  // namespace pkslam
