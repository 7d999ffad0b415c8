// Visual-inertial motion-only optimisation of one body state (ORB-SLAM3's
// PoseInertialOptimizationLastKeyFrame / ...LastFrame) in Ceres: the body pose, velocity and
// biases against matched 3-D points (reprojection on the body pose,
// imu/body_reprojection_error.h) and the preintegration from a previous state, which is either
// fixed (a keyframe, right after the map changed) or free with a prior (the previous frame,
// with the marginal information of its own optimisation). Rounds re-classify outliers as
// estimators/optim/pose_solve.h. Takes and returns values; the frame side is
// tracking/inertial_pose_optimizer.h.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "core/imu/imu_types.h"
#include "estimators/optim/pose_correspondences.h"
#include "estimators/optim/pose_solve.h"
#include "imu/body_reprojection_error.h"

namespace pkslam {

using InertialInformation = Eigen::Matrix<double, 15, 15>;

struct InertialPoseInput {
  NavState previous_state;
  ImuBias previous_bias;
  // Information of the previous state in the order [rho; phi; v; b_g; b_a] (the tangent of
  // InertialStatePriorError). Absent: the previous state is fixed.
  std::optional<InertialInformation> previous_information;
  // Preintegration from the previous state to the frame (not null).
  const PreintegratedImu* preintegration = nullptr;
  Eigen::Vector3d gravity_world = Eigen::Vector3d(0, 0, -9.81);
};

struct InertialPoseOutput {
  int inliers = 0;
  NavState state;  // the frame's body state
  ImuBias bias;
  // Marginal information of (state, bias) in the order of InertialPoseInput (the previous
  // state marginalised out): the next frame's prior.
  InertialInformation information = InertialInformation::Zero();
};

// Starts at (initial_state, initial_bias): the body state and biases of the frame being
// optimised. Every correspondence ends classified as in SolvePose (`block` null exactly for the
// outliers at the returned state).
InertialPoseOutput SolveInertialPose(const BodyCamera& camera, const NavState& initial_state,
                                     const ImuBias& initial_bias,
                                     std::vector<PoseCorrespondence>* correspondences,
                                     const InertialPoseInput& input,
                                     const PoseOptimizerOptions& options);

}  // namespace pkslam
