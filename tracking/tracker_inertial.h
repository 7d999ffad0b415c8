// The tracker's inertial working state (inertial sensors only; owned by the Tracker, used by
// the tracking thread only). The logic is in tracker_inertial.cc.
#pragma once

#include <cstdint>
#include <optional>

#include "core/imu/imu_types.h"
#include "map_model/map_ids.h"
#include "tracking/imu_buffer.h"
#include "tracking/inertial_pose_optimizer.h"
#include "tracking/world_change_cursor.h"

namespace pkslam {

struct InertialTrackingState {
  explicit InertialTrackingState(const ImuNoise& noise) : samples(noise) {}

  // IMU samples not yet consumed, trimmed to what the oldest anchor (last keyframe, last
  // frame, monocular initial frame) still needs.
  ImuBuffer samples;
  std::int64_t last_frame_t_ns = -1;
  // What was last seen of the current map's world changes; the fields below refer to it.
  WorldChangeCursor world;
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
