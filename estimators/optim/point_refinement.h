// Structure-only refinement: every point of a BundleProblem moved to minimise its own
// reprojection errors with all keyframe poses held (independent 3x3 Gauss-Newton problems with
// a Huber kernel, ORB-SLAM's chi2 thresholds). After a calibration change the points that the
// (thinned) calibration adjustment did not hold still sit where the old calibration put them;
// this moves all of them to the new one at a fraction of a bundle adjustment's cost. Stereo and
// monocular observations (RGB-D depth weighting is not modelled).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "estimators/optim/bundle_adjustment.h"

namespace pkslam {

struct PointRefinementOptions {
  int iterations = 5;
  double chi2_mono = 5.991;    // Huber thresholds (chi2 of the whitened residual)
  double chi2_stereo = 7.815;
  // A point moves only if its cost drops and it stays in front of every observing keyframe.
  void Check() const;
};

// Refined positions per problem point (unchanged where the refinement does not lower the cost
// or a point has fewer than 3 residual rows).
std::vector<Eigen::Vector3d> RefinePoints(const BundleProblem& problem,
                                          const PointRefinementOptions& options = {});

}  // namespace pkslam
