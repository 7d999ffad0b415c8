// The estimated inertial state of a body (value types shared by the estimators and the map
// model): velocity and biases at one instant, and the Gaussian prior on a keyframe's 15-D state
// that the local inertial BA's marginalisation leaves (estimators/inertial/marginalization.h).
// Frames and keyframes carry them through map_model/keyframe_inertial.h.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "core/imu/imu_types.h"
#include "core/util/ids.h"

namespace pkslam {

// Velocity and biases of the body at one instant; `valid` once the map's IMU is initialised
// (before that the velocity is unknown and the biases are the prior, zero).
struct InertialState {
  Eigen::Vector3d velocity_world = Eigen::Vector3d::Zero();  // [m/s], world frame
  ImuBias bias;
  bool valid = false;
};

// Gaussian prior on a keyframe's 15-D state that summarises the states marginalised before it
// (the local inertial BA's marginalisation prior, estimators/inertial/marginalization.h). Written
// and read by local mapping under the Atlas mutex. Valid only while the map it was computed in
// has not moved map-wide: `map_id`, `map_change_index` (Map::change_index: loop corrections,
// merges, global and full inertial BA) and `world_transforms` (Map::NumWorldTransforms) must
// still match.
struct InertialStatePrior {
  NavState mean;  // world_from_body and velocity at the prior's mean
  ImuBias bias_mean;
  // In the tangent order [rho, phi, v, b_g, b_a] of InertialStatePriorError (imu/imu_factors.h).
  Eigen::Matrix<double, 15, 15> information = Eigen::Matrix<double, 15, 15>::Zero();
  // A known square root W (W^T W = information) for priors built from one (the gauge of
  // estimators/inertial/gravity_gauge.h); otherwise the factor takes it from an
  // eigen-decomposition, which for a rank-deficient prior adds rows of rounding-noise weight in
  // arbitrary directions.
  std::optional<Eigen::Matrix<double, 15, 15>> sqrt_information;
  MapId map_id = -1;
  int map_change_index = 0;
  int world_transforms = 0;
};

}  // namespace pkslam
