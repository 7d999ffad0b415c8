// Visual-inertial motion-only optimisation of one frame (ORB-SLAM3's
// PoseInertialOptimizationLastKeyFrame / ...LastFrame): the frame side of SolveInertialPose
// (estimators/inertial/inertial_pose_solve.h) — collects the frame's correspondences, solves,
// and writes the pose, the outlier flags and the inertial state back. Reads map-point
// positions: caller holds the Atlas mutex (shared).
#pragma once

#include "estimators/inertial/inertial_pose_solve.h"
#include "map_model/frame.h"

namespace pkslam {

// Starts from frame->camera_from_world() (must be set), frame->imu.state.velocity_world and
// frame->imu.state.bias; writes the refined pose, frame->outliers and frame->imu.state.
InertialPoseOutput OptimizeInertialPose(Frame* frame, const InertialPoseInput& input,
                                        const PoseOptimizerOptions& options = {});

}  // namespace pkslam
