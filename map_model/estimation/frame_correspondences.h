// The frame side of the pose optimisations' correspondences (estimators/optim/
// pose_correspondences.h): collected from a frame's map-point observations, and the outlier
// flags written back to the frame.
#pragma once

#include <vector>

#include "estimators/optim/pose_correspondences.h"
#include "map_model/frame.h"

namespace pkslam {

// One entry per keypoint with a map point. `depth_information`: fill disparity_inv_sigma2
// from the frame (the visual optimiser weighs RGB-D depth readings; the inertial one does not).
std::vector<PoseCorrespondence> CollectPoseCorrespondences(const Frame& frame,
                                                           bool depth_information);

// Rewrites every outlier flag of the frame (no stale flag survives on a slot matched later):
// set for the correspondences left out of the problem. Returns how many.
int WriteOutlierFlags(const std::vector<PoseCorrespondence>& correspondences, Frame* frame);

}  // namespace pkslam
