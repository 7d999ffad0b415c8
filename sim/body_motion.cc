#include "sim/body_motion.h"

#include <utility>

namespace pkslam::sim {

BodyMotion::BodyMotion(SplineTrajectory spline) : spline_(std::move(spline)) {}

BodyMotion::BodyMotion(SplineTrajectory spline, Vibration vibration)
    : spline_(std::move(spline)), vibration_(std::move(vibration)) {}

SE3d BodyMotion::WorldFromBody(std::int64_t t_ns) const {
  if (!vibration_) return spline_.WorldFromBody(t_ns);
  return State(t_ns).world_from_body;
}

BodyState BodyMotion::State(std::int64_t t_ns) const {
  BodyState s = spline_.State(t_ns);
  if (!vibration_) return s;
  return PerturbState(s, vibration_->At(1e-9 * static_cast<double>(t_ns - spline_.begin_ns())));
}

}  // namespace pkslam::sim
