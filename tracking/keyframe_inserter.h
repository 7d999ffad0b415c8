// The keyframe side of a tracked frame: what the selector sees of it (selector_snapshot.h, with
// the IMU intervals and local mapping's state), its decision with tracking's overrides
// (keyframe_decision.h), and the new keyframe when the decision inserts one: made with its close
// points and inertial link (keyframe_points.h), shown to the selector, handed to local mapping.
// Owns the decision and its trace. Tracking thread.
#pragma once

#include <functional>
#include <optional>

#include "core/sensor/camera_rig.h"
#include "keyframe/keyframe_selector.h"
#include "map_model/mapping_backend.h"
#include "tracking/inertial_tracking.h"
#include "tracking/keyframe_decision.h"
#include "tracking/keyframe_points.h"
#include "tracking/tracked_frames.h"
#include "tracking/tracking_options.h"

namespace pkslam {

class Atlas;
class Vocabulary;

// What the inserter reads of the tracker for one frame.
struct KeyFrameContext {
  const CameraRig* rig = nullptr;
  bool recently_lost = false;
  const InertialTracking* imu = nullptr;  // null for visual sensors
  // Whether the map's IMU is initialised, asked under the Atlas lock each time the selector's
  // view is taken.
  std::function<bool()> imu_ready;
  AttachKeyFrame attach;  // a new keyframe's inertial link
};

class KeyFrameInserter {
 public:
  // `options` is the Tracker's own (new_keyframe_min_close_points, lockstep).
  KeyFrameInserter(Atlas* atlas, const Vocabulary* vocabulary, KeyframeSelector* selector,
                   MappingBackend* mapping, const TrackingOptions& options, bool monocular);

  // The selector's view of the tracked frame, with local mapping `mapping_idle` at its time
  // (Atlas lock held, shared).
  SelectorInput Snapshot(const KeyFrameContext& context, const TrackedFrames& frames,
                         bool mapping_idle) const;
  // The snapshot and the decision on it (decision()), traced when asked. `declined_queue_full`
  // is set when local mapping's full queue turned a keyframe down. Atlas lock held (shared).
  SelectorInput Decide(const KeyFrameContext& context, const TrackedFrames& frames,
                       bool mapping_idle, bool* declined_queue_full);
  // The current frame becomes a keyframe (map write lock taken here): it is the reference and
  // the newest keyframe from now on, the selector learns what it holds (after creation when the
  // selector asks: SnapshotAfterCreation) and local mapping gets it (waiting until it is done
  // under TrackingOptions::lockstep). No Atlas lock held by the caller.
  KeyFramePtr Insert(const KeyFrameContext& context, const SelectorInput& input,
                     TrackedFrames* frames);

  // The decision made for frame `frame_id`, or null when the last decision was another frame's
  // (a frame tracked in localisation mode, switched on at run time, has none).
  const SelectorDecision* DecisionFor(FrameId frame_id) const {
    return decided_frame_ == frame_id ? &decision_.last() : nullptr;
  }
  const std::vector<KeyFrameTraceRow>& trace() const { return decision_.trace(); }
  void EnableTrace(bool on) { decision_.EnableTrace(on); }

 private:
  Atlas* atlas_;
  const Vocabulary* vocabulary_;
  KeyframeSelector* selector_;
  MappingBackend* mapping_;
  const TrackingOptions& options_;
  KeyFrameDecision decision_;
  std::optional<FrameId> decided_frame_;  // the frame decision_.last() was made for
};

}  // namespace pkslam
