// Motion-only bundle adjustment of one frame against its matched map points (ORB-SLAM's
// PoseOptimization) in Ceres: monocular (u, v) and stereo/RGB-D (u, v, u_right) residuals
// weighted by the keypoint octave, Huber loss, several rounds that re-classify outliers.
// The frame side: collects the frame's correspondences, runs SolvePose
// (estimators/optim/pose_solve.h) and writes the pose and outlier flags back. Reads map-point
// positions: caller holds the Atlas mutex (shared).
#pragma once

#include "estimators/optim/pose_solve.h"
#include "map_model/frame.h"

namespace pkslam {

// Refines frame->camera_from_world() (must be set) using frame->map_points; writes
// frame->outliers. Returns the number of inlier correspondences (0 if fewer than 3 matches).
int OptimizePose(Frame* frame, const PoseOptimizerOptions& options = {});

}  // namespace pkslam
