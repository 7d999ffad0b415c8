// The motion the simulator renders and measures: the smooth spline trajectory (replayed ground
// truth or a random flight), optionally moved by rotor vibration. Both the renderer and the IMU
// query this one object, so images and inertial measurements describe the same motion.
// A value type; const methods are thread-safe.
#pragma once

#include <cstdint>
#include <optional>

#include "sim/motion_trajectory.h"
#include "sim/vibration.h"

namespace pkslam::sim {

class BodyMotion {
 public:
  explicit BodyMotion(SplineTrajectory spline);
  // The vibration's time origin is the spline's begin.
  BodyMotion(SplineTrajectory spline, Vibration vibration);

  std::int64_t begin_ns() const { return spline_.begin_ns(); }
  std::int64_t end_ns() const { return spline_.end_ns(); }
  bool vibrates() const { return vibration_.has_value(); }

  SE3d WorldFromBody(std::int64_t t_ns) const;
  BodyState State(std::int64_t t_ns) const;
  // The smooth motion without vibration.
  const SplineTrajectory& spline() const { return spline_; }

 private:
  SplineTrajectory spline_;
  std::optional<Vibration> vibration_;
};

}  // namespace pkslam::sim
