// Point-to-point ICP (Besl & McKay 1992), the registration of seed 001 (section 2, Eqs. 3-4):
// each iteration pairs every source point (moved by the current estimate) with its nearest
// target point (core/geometry/point_cloud_index.h), optionally drops pairs farther apart than a
// rejection distance, and solves the closed-form rigid alignment of the pairs (rigid_alignment.h).
// It stops when an update moves the estimate by less than the tolerances, or when the mean
// squared error stops decreasing by more than a relative tolerance.
//
// Acceleration (Besl & McKay's "accelerated ICP", their section IV-C): point-to-point ICP
// creeps when surfaces slide along each other. When the last three estimates move in nearly the
// same direction (successive updates within 10 degrees, in the 6-D [translation; rotation]
// tangent), the error along that line is modelled by a line and a parabola through the last
// three (distance, error) points and the estimate jumps to the parabola's minimum (or the
// line's zero), at most 25 update lengths ahead.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/geometry/point_cloud_index.h"
#include "core/geometry/se3.h"

namespace pkslam::rgbd {

using pkslam::PointCloudIndex;

struct IcpOptions {
  int max_iterations = 50;
  // Converged when an update changes the estimate by less than both of these.
  double min_update_translation_m = 1e-5;
  double min_update_rotation_rad = 1e-5;
  // Converged when the MSE decreases by less than this fraction (Besl-McKay's tau).
  double min_relative_mse_decrease = 1e-6;
  // Pairs farther apart than this are ignored [m]; 0 = keep all (the original algorithm,
  // which assumes the source lies entirely within the target's extent).
  double max_correspondence_m = 0.10;
  // Besl-McKay acceleration (see above). Off by default: on the simulated room sequence the
  // jumps sent a few plane-sample registrations 13-50 cm astray (gaps 2-5) that plain ICP
  // solves to ~1 cm.
  bool accelerate = false;

  void Check() const;
};

struct IcpResult {
  bool success = false;    // a solution from at least 3 pairs in every iteration
  bool converged = false;  // stopped by a tolerance, not by max_iterations
  SE3d target_from_source;
  int iterations = 0;
  int accelerations = 0;    // extrapolation jumps taken
  int correspondences = 0;  // pairs in the last iteration
  double rmse_m = 0;        // RMS pair distance in the last iteration (before its update)
};

IcpResult IcpPointToPoint(const std::vector<Eigen::Vector3f>& source, const PointCloudIndex& target,
                          const SE3d& initial_target_from_source, const IcpOptions& options);

}  // namespace pkslam::rgbd
