#include "sim/motion_trajectory.h"

#include <algorithm>
#include <cmath>

#include "core/util/error.h"
#include "sim/spline_fit.h"

namespace pkslam::sim {

SplineTrajectory::SplineTrajectory(PositionSpline6 position, RotationSpline4 rotation)
    : position_(std::move(position)), rotation_(std::move(rotation)) {
  begin_ns_ = std::max(position_.grid().t0_ns, rotation_.grid().t0_ns);
  end_ns_ = std::min(position_.grid().end_ns(), rotation_.grid().end_ns());
  PKSLAM_CHECK(end_ns_ > begin_ns_, "position and rotation splines do not overlap");
}

SE3d SplineTrajectory::WorldFromBody(std::int64_t t_ns) const {
  return SE3d(rotation_.Evaluate(t_ns), position_.Evaluate(t_ns));
}

BodyState SplineTrajectory::State(std::int64_t t_ns) const {
  BodyState s;
  s.t_ns = t_ns;
  const Eigen::Vector3d p = position_.Evaluate(t_ns, &s.velocity_world, &s.acceleration_world);
  s.world_from_body = SE3d(rotation_.Evaluate(t_ns, &s.omega_body, &s.alpha_body), p);
  return s;
}

void ReplayOptions::Check() const {
  PKSLAM_CHECK_OPTION(position_knot_s >= 0.005 && position_knot_s <= 1.0, "position_knot_s", "{}",
                      position_knot_s);
  PKSLAM_CHECK_OPTION(rotation_knot_s >= 0.005 && rotation_knot_s <= 1.0, "rotation_knot_s", "{}",
                      rotation_knot_s);
  PKSLAM_CHECK_OPTION(padding_s >= 0.0, "padding_s", "{}", padding_s);
}

SplineTrajectory FitTrajectory(const std::vector<StampedPose>& samples, std::int64_t begin_ns,
                               std::int64_t end_ns, const ReplayOptions& options) {
  options.Check();
  PKSLAM_CHECK(samples.size() >= 2, "trajectory has {} poses", samples.size());
  PKSLAM_CHECK(end_ns > begin_ns, "empty replay window");
  const auto pad = static_cast<std::int64_t>(std::llround(options.padding_s * 1e9));
  const std::int64_t lo = std::max(samples.front().t_ns, begin_ns - pad);
  const std::int64_t hi = std::min(samples.back().t_ns, end_ns + pad);
  PKSLAM_CHECK(begin_ns >= samples.front().t_ns && end_ns <= samples.back().t_ns,
               "replay window [{}, {}] ns outside the trajectory [{}, {}]", begin_ns, end_ns,
               samples.front().t_ns, samples.back().t_ns);
  std::vector<std::int64_t> t;
  std::vector<Eigen::Vector3d> p;
  std::vector<SO3d> r;
  for (const auto& s : samples) {
    if (s.t_ns < lo || s.t_ns > hi) continue;
    t.push_back(s.t_ns);
    p.push_back(s.pose.translation());
    r.push_back(s.pose.so3());
  }
  auto knot = [](double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); };
  const KnotGrid pgrid = KnotGrid::Covering(t.front(), t.back(), knot(options.position_knot_s));
  const KnotGrid rgrid = KnotGrid::Covering(t.front(), t.back(), knot(options.rotation_knot_s));
  return SplineTrajectory(FitPositionSpline(t, p, pgrid, options.position_cutoff_hz),
                          FitRotationSpline(t, r, rgrid, options.rotation_cutoff_hz));
}

double PathLength(const std::vector<Eigen::Vector3d>& positions) {
  double length = 0.0;
  for (std::size_t i = 1; i < positions.size(); ++i) {
    length += (positions[i] - positions[i - 1]).norm();
  }
  return length;
}

}  // namespace pkslam::sim
