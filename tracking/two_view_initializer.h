// Monocular map initialisation from two views (ORB-SLAM's Initializer / TwoViewReconstruction):
// homography and fundamental matrix estimated in parallel by RANSAC on the same minimal sets,
// scored by symmetric transfer error; the model is chosen by R_H = S_H / (S_H + S_F) > 0.4;
// the motion is recovered (H: Faugeras decomposition, 8 hypotheses; F: E = K^T F K, 4
// hypotheses) and the hypothesis is accepted only if it is clearly the best by number of
// triangulated points in front of both cameras with enough parallax.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/frame/frame.h"
#include "core/geometry/se3.h"

namespace pkslam {

struct TwoViewOptions {
  // Keypoint position sigma (pixels at level 0).
  double sigma = 1.0;
  // RANSAC iterations (shared by the two models).
  int iterations = 200;
  // Minimum parallax (degrees) and triangulated points to accept a reconstruction.
  double min_parallax_deg = 1.0;
  int min_triangulated = 50;
  // RNG seed (fixed in deterministic mode).
  std::uint64_t seed = 0;

  void Check() const;
};

struct TwoViewResult {
  // Pose of the second camera w.r.t. the first (first = world, unit-less scale).
  SE3d camera2_from_camera1;
  // Per keypoint of the first frame: triangulated point in camera-1 coordinates.
  std::vector<Eigen::Vector3d> points;
  std::vector<bool> triangulated;
  bool used_homography = false;
  double parallax_deg = 0;
};

// matches12[i1] = index of the matched keypoint in `second` or -1. Works on undistorted
// keypoints with the rig's pinhole K. nullopt when no reliable reconstruction exists.
std::optional<TwoViewResult> ReconstructTwoView(const Frame& first, const Frame& second,
                                                const std::vector<int>& matches12,
                                                const TwoViewOptions& options);

}  // namespace pkslam
