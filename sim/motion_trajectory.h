// The simulator's ground-truth motion: a body (IMU) trajectory given by a quintic position
// spline and a cubic SO(3) spline, with analytic derivatives at any time. Built either by
// replaying a recorded trajectory (smoothing fit) or by the random motion generator.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "core/geometry/se3.h"
#include "io/trajectory.h"
#include "sim/bspline.h"

namespace pkslam::sim {

// Full kinematic state of the body at one instant.
struct BodyState {
  std::int64_t t_ns = 0;
  SE3d world_from_body;
  Eigen::Vector3d velocity_world = Eigen::Vector3d::Zero();      // m/s
  Eigen::Vector3d acceleration_world = Eigen::Vector3d::Zero();  // m/s^2 (no gravity)
  Eigen::Vector3d omega_body = Eigen::Vector3d::Zero();          // rad/s
  Eigen::Vector3d alpha_body = Eigen::Vector3d::Zero();          // rad/s^2
};

class SplineTrajectory {
 public:
  SplineTrajectory() = default;
  SplineTrajectory(PositionSpline6 position, RotationSpline4 rotation);

  // Valid time range (intersection of both splines' grids).
  std::int64_t begin_ns() const { return begin_ns_; }
  std::int64_t end_ns() const { return end_ns_; }

  SE3d WorldFromBody(std::int64_t t_ns) const;
  BodyState State(std::int64_t t_ns) const;

  const PositionSpline6& position() const { return position_; }
  const RotationSpline4& rotation() const { return rotation_; }

 private:
  PositionSpline6 position_;
  RotationSpline4 rotation_;
  std::int64_t begin_ns_ = 0;
  std::int64_t end_ns_ = 0;
};

// Smoothing options for replaying recorded (motion-capture) poses.
struct ReplayOptions {
  double position_knot_s = 0.05;     // knot spacing of the quintic position spline
  double rotation_knot_s = 0.05;     // knot spacing of the cubic rotation spline
  double position_cutoff_hz = 10.0;  // low-pass cutoff of the jerk penalty (<= 0: none)
  double rotation_cutoff_hz = 10.0;  // same for angular acceleration (<= 0: none)
  double padding_s = 1.0;            // extra data fitted beyond the window on each side

  void Check() const;
};

// Fits the poses (world_from_body, e.g. from io/trajectory.h) around [begin_ns, end_ns] plus
// padding where data exists. Throws Error when the window holds too few samples.
SplineTrajectory FitTrajectory(const std::vector<StampedPose>& samples, std::int64_t begin_ns,
                               std::int64_t end_ns, const ReplayOptions& options);

// Path length (m) of sampled positions.
double PathLength(const std::vector<Eigen::Vector3d>& positions);

}  // namespace pkslam::sim
