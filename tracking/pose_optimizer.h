// Motion-only bundle adjustment of one frame against its matched map points (ORB-SLAM's
// PoseOptimization) in Ceres: monocular (u, v) and stereo/RGB-D (u, v, u_right) residuals
// weighted by the keypoint octave, Huber loss, several rounds that re-classify outliers.
// Reads map-point positions: caller holds the Atlas mutex (shared).
#pragma once

#include "map_model/frame.h"

namespace pkslam {

struct PoseOptimizerOptions {
  // Rounds of optimisation; after each, every correspondence is re-classified by its chi2.
  int rounds = 4;
  // Solver iterations per round.
  int iterations_per_round = 10;
  // chi2 thresholds (95%, 2 and 3 DoF) for monocular and stereo residuals.
  double chi2_mono = 5.991;
  double chi2_stereo = 7.815;
  // Rounds (from the first) that use the Huber loss; later rounds use plain least squares
  // (ORB-SLAM removes the kernel after its third round).
  int robust_rounds = 3;
  // Ceres threads (1 in deterministic mode).
  int num_threads = 1;

  void Check() const;
};

// Refines frame->camera_from_world() (must be set) using frame->map_points; writes
// frame->outliers. Returns the number of inlier correspondences (0 if fewer than 3 matches).
int OptimizePose(Frame* frame, const PoseOptimizerOptions& options = {});

}  // namespace pkslam
