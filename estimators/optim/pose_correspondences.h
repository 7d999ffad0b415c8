// What the visual and the inertial pose optimisations share (values, no frame): one
// correspondence per matched keypoint with its cost function and residual block while it is an
// inlier, and the per-round re-classification into inliers and outliers. The frame side
// (collecting them from a Frame, writing the outlier flags back) is
// map_model/estimation/frame_correspondences.h.
#pragma once

#include <ceres/cost_function.h>
#include <ceres/problem.h>

#include <Eigen/Core>
#include <memory>
#include <vector>

namespace pkslam {

struct PoseCorrespondence {
  int keypoint = -1;
  bool stereo = false;
  Eigen::Vector3d p_world;
  Eigen::Vector3d obs;  // u, v, u_right (u_right unused for monocular)
  double inv_sigma2 = 1.0;
  double disparity_inv_sigma2 = 0.0;  // RGB-D depth reading's information (0: stereo form)
  std::unique_ptr<ceres::CostFunction> cost;
  ceres::ResidualBlockId block = nullptr;  // null while classified as outlier
};

// Re-classifies every correspondence (outliers too) at the new estimate: chi2(c) against the
// mono or stereo threshold; a new inlier goes back in through add(c), a new outlier's residual
// block leaves the problem. Returns the number of inliers.
template <class Chi2, class Add>
int ReclassifyCorrespondences(std::vector<PoseCorrespondence>* correspondences,
                              ceres::Problem* problem, double chi2_mono, double chi2_stereo,
                              const Chi2& chi2, const Add& add) {
  int inliers = 0;
  for (PoseCorrespondence& c : *correspondences) {
    const bool inlier = chi2(c) <= (c.stereo ? chi2_stereo : chi2_mono);
    if (inlier && c.block == nullptr) add(c);
    if (!inlier && c.block != nullptr) {
      problem->RemoveResidualBlock(c.block);
      c.block = nullptr;
    }
    inliers += inlier ? 1 : 0;
  }
  return inliers;
}

}  // namespace pkslam
