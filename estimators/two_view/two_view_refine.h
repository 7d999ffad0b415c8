// Calibrated refinement of a two-view motion: Levenberg-Marquardt on the Sampson error of
// E = [t]x R over well-triangulated correspondences (5 DoF: rotation and the direction of t).
// The eight-point F ignores the known intrinsics (7 DoF), which leaves its translation
// direction a degree or two off at 1 px noise; this step uses K. Pure function; thread-safe.
#pragma once

#include <cstdint>
#include <vector>

#include "estimators/two_view/two_view_models.h"
#include "estimators/two_view/two_view_motion.h"

namespace pkslam::two_view {

struct MotionRefinement {
  Motion motion;
  double initial_rms = 0;  // Sampson error (normalised units) before / after
  double final_rms = 0;
  int iterations = 0;
};

// normalized: points on the z = 1 planes; only correspondences with mask[i] != 0 count
// (at least 5 are needed, else the motion is returned unchanged).
MotionRefinement RefineMotion(const Motion& initial, const Correspondences& normalized,
                              const std::vector<std::uint8_t>& mask, int max_iterations = 30);

// Correspondences whose |Sampson error| under `motion` is at most max_error (normalised
// units), as a mask.
std::vector<std::uint8_t> SampsonInliers(const Motion& motion, const Correspondences& normalized,
                                         double max_error);

// Sampson error of x2^T E x1 = 0 for normalised points (first-order geometric distance).
double SampsonError(const Eigen::Matrix3d& e21, const Eigen::Vector2d& x1,
                    const Eigen::Vector2d& x2);

}  // namespace pkslam::two_view
