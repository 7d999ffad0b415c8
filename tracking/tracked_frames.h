// What tracking keeps from one frame to the next: the frame being tracked, the last one, the
// motion model and the keyframes they hang from. A value owned by the Tracker; its parts
// (map_tracker.h, the keyframe and inertial steps) read and move it in the tracking thread.
#pragma once

#include <optional>

#include "core/geometry/se3.h"
#include "map_model/frame.h"
#include "map_model/keyframe.h"
#include "map_model/map_ids.h"

namespace pkslam {

struct TrackedFrames {
  Frame current;
  Frame last;
  std::optional<SE3d> velocity;  // camera_from_world(current) * world_from_camera(last)
  KeyFramePtr reference_kf;      // the keyframe sharing most points with the current frame
  KeyFramePtr last_kf;           // the newest keyframe tracking created
  FrameId last_reloc_frame_id = -1000000;
  int inliers = 0;  // the current frame's inliers to map points after the local map

  // The frame right after a relocalisation: its motion model is not trusted (ORB-SLAM3's
  // "mnLastRelocFrameId + 2").
  bool JustRelocalised() const { return current.id() < last_reloc_frame_id + 2; }
  // Within `frames` frames of a relocalisation, which must then be confirmed by more inliers.
  bool WithinFramesOfRelocalisation(int frames) const {
    return current.id() < last_reloc_frame_id + frames;
  }
};

}  // namespace pkslam
