// Motion-only bundle adjustment of one camera pose against known 3-D points (ORB-SLAM's
// PoseOptimization) in Ceres: monocular (u, v) and stereo/RGB-D (u, v, u_right) residuals
// weighted by the keypoint octave, Huber loss, several rounds that re-classify outliers. Takes
// values (intrinsics, initial pose, correspondences), returns the pose; the frame side is
// tracking/pose_optimizer.h.
#pragma once

#include <vector>

#include "core/geometry/pinhole_intrinsics.h"
#include "core/geometry/se3.h"
#include "estimators/optim/pose_correspondences.h"

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

// The refined camera_from_world. Every correspondence ends classified: its `block` is null
// exactly when it is an outlier at the returned pose (only that flag survives the call; the
// blocks themselves belonged to the solver's problem). At least one correspondence.
SE3d SolvePose(const PinholeIntrinsics& k, const SE3d& initial_camera_from_world,
               std::vector<PoseCorrespondence>* correspondences,
               const PoseOptimizerOptions& options);

}  // namespace pkslam
