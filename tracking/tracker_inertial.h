// The tracker's inertial working state (inertial sensors only; owned by the Tracker, used by
// the tracking thread only). The logic is in tracker_inertial.cc.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>

#include "core/imu/imu_types.h"
#include "map_model/map_ids.h"
#include "tracking/inertial_pose_optimizer.h"

namespace pkslam {

struct InertialTrackingState {
  // IMU samples not yet consumed, time-ordered; trimmed to what the oldest anchor (last
  // keyframe, last frame, monocular initial frame) still needs.
  std::deque<ImuMeasurement> queue;
  std::int64_t last_frame_t_ns = -1;
  // The map the fields below refer to and what was last seen of its inertial changes.
  const Map* map = nullptr;
  int seen_world_changes = 0;  // cursor into the map's world-change log
  double seen_scale = 1.0;
  // Predict and optimise against the last keyframe (true after the map changed under us)
  // instead of the last frame.
  bool from_keyframe = true;
  // Marginal information of the last frame's state (its inertial optimisation), and the
  // frame it belongs to.
  std::optional<InertialInformation> last_frame_information;
  FrameId information_frame_id = kInvalidId;
  // Gravity in the (gravity-aligned) world of an initialised map.
  double gravity_magnitude = 9.81;
};

}  // namespace pkslam
