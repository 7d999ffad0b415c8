// ORB-SLAM3's inertial-only initialisation (LocalMapping::InitializeIMU +
// Optimizer::InertialOptimization) as a pure function: with the keyframe poses from vision held
// fixed (known up to scale for monocular), find the maximum a posteriori gravity direction,
// scale, one gyro and one accel bias shared by all keyframes, and a velocity per keyframe, from
// the IMU preintegrations between consecutive keyframes and zero-mean bias priors.
//
// Applying the result (the caller's job, ORB-SLAM3's Map::ApplyScaledRotation): with
// R_gw = world_from_gravity^-1, the gravity-aligned metric map has
//   world_from_body' = (R_gw, 0) * (R_wb, scale * p_wb),   v' = scale * R_gw * v,
// and gravity (0, 0, -gravity_magnitude) in it.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "core/geometry/se3.h"
#include "core/geometry/so3.h"
#include "core/imu/imu_types.h"

namespace pkslam {

struct InertialInitializerOptions {
  // Gravity magnitude [m/s^2] (ORB-SLAM3's IMU::GRAVITY_VALUE).
  double gravity_magnitude = 9.81;
  // Estimate the scale (monocular); false keeps it at 1 (stereo / RGB-D).
  bool estimate_scale = true;
  // Information (1/sigma^2) of the zero-mean gyro-bias prior (ORB-SLAM3 priorG = 1e2).
  double gyro_bias_prior_information = 1e2;
  // Information of the zero-mean accel-bias prior (ORB-SLAM3 priorA: 1e10 monocular, which
  // pins the accel bias at zero while scale is unknown; 1e5 stereo).
  double accel_bias_prior_information = 1e10;
  // Levenberg-Marquardt iterations (ORB-SLAM3 uses 200).
  int max_iterations = 200;
  // A solution with scale below this is rejected (ORB-SLAM3 aborts below 0.1).
  double min_scale = 0.1;
  // A time gap between consecutive keyframes that differs from the preintegration's dt by more
  // than this [s] is a caller error.
  double time_tolerance = 1e-6;

  void Check() const;
};

// A keyframe as the initialiser sees it: its time and its visual body pose.
struct InertialInitKeyFrame {
  std::int64_t t_ns = 0;
  SE3d world_from_body;  // up to scale when monocular
};

struct InertialInitResult {
  bool success = false;
  std::string message;  // why it failed (empty on success)
  // Rotation from the gravity frame (gravity along -z) to the poses' world frame; its yaw about
  // the gravity axis is arbitrary (unobservable).
  SO3d world_from_gravity;
  Eigen::Vector3d gravity_world = Eigen::Vector3d::Zero();  // R_wg (0, 0, -gravity_magnitude)
  double scale = 1.0;                                       // metric = scale * input units
  ImuBias bias;
  // Per keyframe, in the poses' world frame and units (metric velocity = scale * v).
  std::vector<Eigen::Vector3d> velocities_world;
  double initial_cost = 0;
  double final_cost = 0;
  int iterations = 0;
};

// Unit gravity direction in the poses' world frame: normalised -sum_k R_wb_k dv_k(bias), over
// the preintegrations between consecutive keyframes (preintegrations[k]: keyframe k -> k + 1).
// The velocity changes cancel over the sum and leave g * total time. Requires >= 1 interval.
Eigen::Vector3d EstimateGravityDirection(const std::vector<InertialInitKeyFrame>& keyframes,
                                         const std::vector<PreintegratedImu>& preintegrations,
                                         const ImuBias& bias);

// Solves the inertial-only MAP problem. keyframes: >= 2, increasing in time;
// preintegrations[k] spans keyframes k -> k + 1 (so size() == keyframes.size() - 1), linearised
// at any bias (the first-order correction is used). `initial_bias` starts the biases; the
// velocities start at forward differences of the positions and R_wg at
// EstimateGravityDirection. Throws Error on inconsistent inputs; returns success = false when
// the solver fails or the scale is implausible (< min_scale or not finite).
InertialInitResult InitializeInertial(const std::vector<InertialInitKeyFrame>& keyframes,
                                      const std::vector<PreintegratedImu>& preintegrations,
                                      const ImuBias& initial_bias,
                                      const InertialInitializerOptions& options);

}  // namespace pkslam
