// Tracking's keyframe decision on a tracked frame: the selector's (keyframe/), with tracking's
// two overrides. A monocular map about to starve of keyframes gets one even while local mapping
// is busy (ORB-SLAM3's NeedNewKeyFrame: few inliers, or too few against the reference
// keyframe); none is made while local mapping's queue is full (the backpressure of
// LocalMappingOptions::max_queued_keyframes), whatever the selector says. Decisions are traced
// on request (pkslam run --trace). Owned by the Tracker, tracking thread only.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "keyframe/keyframe_selector.h"
#include "map_model/map_ids.h"

namespace pkslam {

// One traced decision (keyframe_trace.csv).
struct KeyFrameTraceRow {
  std::int64_t t_ns;
  FrameId frame_id;
  SelectorDecision decision;
  int frames_since_keyframe;
};

// TrackingOptions::starving_inliers / starving_ratio.
struct StarvingRule {
  int min_inliers = 75;
  double min_reference_ratio = 0.5;
};

// Whether a monocular map is about to starve: the selector said no only because local mapping
// is busy and tracking holds fewer than `rule.min_inliers`, or tracking holds fewer than
// `rule.min_reference_ratio` of the reference keyframe's points; never while local mapping is
// idle, stopped, behind by 3 keyframes, or in localisation.
bool MapStarving(const SelectorDecision& decision, const SelectorInput& in, int inliers,
                 const StarvingRule& rule);

// The trace entries named criterion* that held (PKS: criterion1 = D_c > Th, criterion2 =
// ECOG > |COG|).
std::vector<std::string> CriteriaHeld(const SelectorDecision& decision);

class KeyFrameDecision {
 public:
  KeyFrameDecision(bool monocular, StarvingRule rule) : monocular_(monocular), rule_(rule) {}

  // The decision on the frame `in` describes (tracked with `inliers` inliers). `queue_full` is
  // asked only when a keyframe is wanted; `declined_queue_full` is set when it said no.
  const SelectorDecision& Decide(KeyframeSelector& selector, const SelectorInput& in, int inliers,
                                 const std::function<bool()>& queue_full,
                                 bool* declined_queue_full);
  const SelectorDecision& last() const { return last_; }

  void EnableTrace(bool on) { trace_enabled_ = on; }
  bool tracing() const { return trace_enabled_; }
  const std::vector<KeyFrameTraceRow>& trace() const { return trace_; }

 private:
  bool monocular_;
  StarvingRule rule_;
  SelectorDecision last_;
  bool trace_enabled_ = false;
  std::vector<KeyFrameTraceRow> trace_;
};

}  // namespace pkslam
