// Visual-inertial motion-only optimisation of one frame (ORB-SLAM3's
// PoseInertialOptimizationLastKeyFrame / ...LastFrame) in Ceres: the frame's body pose,
// velocity and biases against its matched map points (reprojection on the body pose,
// imu/body_reprojection_error.h) and the preintegration from a previous state, which is either
// fixed (a keyframe, right after the map changed) or free with a prior (the previous frame,
// with the marginal information of its own optimisation). Rounds re-classify outliers as
// tracking/pose_optimizer.h. Reads map-point positions: caller holds the Atlas mutex (shared).
#pragma once

#include <Eigen/Core>
#include <optional>

#include "core/imu/imu_types.h"
#include "map_model/frame.h"
#include "tracking/pose_optimizer.h"

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

// Starts from frame->camera_from_world() (must be set), frame->imu.state.velocity_world and
// frame->imu.state.bias; writes the refined pose, frame->outliers and frame->imu.state.
InertialPoseOutput OptimizeInertialPose(Frame* frame, const InertialPoseInput& input,
                                        const PoseOptimizerOptions& options = {});

}  // namespace pkslam
