#include "mapping/inertial_motion_clock.h"

#include <algorithm>

#include "map_model/keyframe.h"

namespace pkslam {

KeyFrameMotion InertialMotionClock::Observe(const KeyFrame& keyframe, bool refining,
                                            const InertialMappingOptions& options) {
  if (keyframe.map() != map_) {
    map_ = keyframe.map();
    Restart();
  }
  KeyFrameMotion motion;
  const KeyFrame* previous = keyframe.imu().previous();
  if (previous == nullptr || previous->IsBad()) return motion;
  const SE3d previous_from_kf = previous->world_from_body().Inverse() * keyframe.world_from_body();
  if (previous_from_kf.translation().norm() > options.moving_distance ||
      previous_from_kf.so3().Log().norm() > options.moving_angle_rad) {
    motion.step_s = std::min(options.moving_max_interval_s,
                             static_cast<double>(keyframe.t_ns() - previous->t_ns()) * 1e-9);
  }
  const KeyFrame* before = previous->imu().previous();
  if (refining && before != nullptr && !before->IsBad()) {
    const double two_steps = (keyframe.CameraCenter() - previous->CameraCenter()).norm() +
                             (previous->CameraCenter() - before->CameraCenter()).norm();
    if (two_steps > 0.05) two_step_motion_s_ += (keyframe.t_ns() - previous->t_ns()) * 1e-9;
    motion.slow_motion = two_step_motion_s_ < 10.0 && two_steps < 0.1;
  }
  return motion;
}

}  // namespace pkslam
