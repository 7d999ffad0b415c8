// RANSAC around the closed-form rigid alignment (seed 000, section 4-5): random minimal samples
// of 3 correspondences, a model from each, consensus by a distance threshold, and the adaptive
// iteration count N = log(1 - p) / log(1 - w^k) re-evaluated whenever a larger consensus set is
// found (w = its inlier ratio, k = 3). The winner is refitted on all its inliers.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "core/geometry/se3.h"

namespace pkslam::rgbd {

struct RansacOptions {
  // A pair is an inlier when |target - T source| is below this [m]. Kinect depth noise is
  // ~1.5 cm at 3 m, so 3 cm keeps good pairs and rejects wrong matches.
  double inlier_threshold_m = 0.03;
  // p: probability that at least one sample is outlier-free.
  double confidence = 0.99;
  // Cap on N (the formula diverges as w -> 0).
  int max_iterations = 1000;
  // Fewer inliers than this (after the refit) is a failure: the frames do not overlap enough
  // (seed 000: "alignment fails when the inliers are below a user threshold").
  int min_inliers = 20;
  // Seed of the sampler; the result is a pure function of inputs and seed.
  std::uint64_t seed = 1;

  void Check() const;
};

// N = ceil(log(1 - p) / log(1 - w^k)), clamped to [1, max_iterations]; w <= 0 gives
// max_iterations, w >= 1 gives 1.
int RansacIterationCount(double confidence, double inlier_ratio, int sample_size,
                         int max_iterations);

struct RansacResult {
  bool success = false;
  SE3d target_from_source;   // identity when !success
  std::vector<int> inliers;  // indices into the correspondences
  int iterations = 0;        // samples drawn
};

// Robust target_from_source from putative correspondences source[i] <-> target[i].
RansacResult EstimateRigidRansac(std::span<const Eigen::Vector3d> source,
                                 std::span<const Eigen::Vector3d> target,
                                 const RansacOptions& options);

}  // namespace pkslam::rgbd
