// What the keyframe selector sees of a tracked frame (keyframe/keyframe_selector.h's
// SelectorInput): the frame, its tracking and the map around it. The selector decides on this
// snapshot alone, which is what lets a keyframe rule be studied apart from the map; the
// tracker adds its IMU intervals and local mapping's state.
//
// Tracking thread, Atlas lock held (shared): it reads keyframes and map points.
#pragma once

#include "core/sensor/camera_rig.h"
#include "keyframe/keyframe_selector.h"
#include "map_model/frame.h"
#include "map_model/map_ids.h"

namespace pkslam {

class MappingBackend;

struct TrackedFrameView {
  const CameraRig* rig = nullptr;
  const Map* map = nullptr;      // the current map
  const Frame* frame = nullptr;  // tracked: posed, its matches and outlier flags set
  int inliers = 0;
  bool recently_lost = false;
  const KeyFrame* reference = nullptr;      // may be null
  const KeyFrame* last_keyframe = nullptr;  // may be null
  FrameId last_relocalisation_frame_id = -1000000;
};

// The snapshot without the IMU and local-mapping fields. Stereo/RGB-D: counts the close
// keypoints (depth below the rig's th_depth) with and without a tracked point. When
// `selector.NeedsTrackedPoints()`: one SelectorPoint per matched good point (outliers too if
// `selector.NeedsOutliers()`).
SelectorInput SnapshotTrackedFrame(const TrackedFrameView& view, const KeyframeSelector& selector);

// Local mapping's state as the selector sees it: stopped, idle (`idle`: as the caller read it for
// this frame), initialising the IMU, its queue.
void NoteLocalMapping(const MappingBackend& mapping, bool idle, SelectorInput* in);

// A new map's first keyframe is `frame`: the selector starts over from it.
void RestartSelector(const Frame& frame, KeyframeSelector* selector);

}  // namespace pkslam
