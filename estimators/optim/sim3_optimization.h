// ORB-SLAM's OptimizeSim3: refines the similarity between two keyframes that verify a loop or
// merge candidate from their matched map points, minimising the reprojection error of each
// pair in both images (Huber), in two rounds with outlier removal in between. Monocular maps
// optimise the scale; stereo/RGB-D keep it fixed (SE3).
//
// Works on the copied geometry of estimators/ransac/sim3_solver.h (no Atlas lock needed).
// Deterministic: single-threaded Ceres gives identical results for identical inputs.
#pragma once

#include <vector>

#include "core/geometry/pinhole_intrinsics.h"
#include "core/geometry/sim3.h"
#include "estimators/ransac/sim3_solver.h"

namespace pkslam {

struct Sim3OptimizationOptions {
  // A pair is an outlier when its squared reprojection error over sigma^2 exceeds this in
  // either image; it is also the Huber threshold (squared). ORB-SLAM's loop closing: 10.
  double chi2 = 10.0;
  // Keep the scale at its initial value (stereo/RGB-D).
  bool fix_scale = false;
  // Iterations of the first round, and of the second round when the first one found outliers
  // (ORB-SLAM: 5, then 10 after removing outliers, else 5 more).
  int iterations_first = 5;
  int iterations_second = 10;
  // Fewer pairs left after the first round: the optimisation fails (ORB-SLAM: 10).
  int min_pairs_after_first = 10;
  int num_threads = 1;

  void Check() const;
};

struct Sim3OptimizationResult {
  Sim3d camera1_from_camera2;
  std::vector<bool> inliers;  // per match
  int num_inliers = 0;        // 0 when the optimisation failed
  double initial_cost = 0;    // robust cost of the first round (Ceres' 1/2 sum rho)
  double final_cost = 0;      // robust cost at the end of the second round
};

// `initial` maps camera 2 to camera 1 (S12, e.g. from Sim3Solver). Its scale is kept when
// fix_scale is set.
Sim3OptimizationResult OptimizeSim3(const std::vector<Sim3Match>& matches,
                                    const PinholeIntrinsics& camera1,
                                    const PinholeIntrinsics& camera2, const Sim3d& initial,
                                    const Sim3OptimizationOptions& options);

}  // namespace pkslam
