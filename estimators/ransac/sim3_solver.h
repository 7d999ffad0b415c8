// Sim(3) / SE(3) between two keyframes from matched map points, by RANSAC over the closed-form
// alignment of three point pairs (ORB-SLAM's Sim3Solver, used to verify loop and merge
// candidates). Monocular maps estimate the scale; stereo/RGB-D fix it to 1.
//
// The solver works on a copy of the geometry (MakeSim3Matches reads the keyframes under the
// Atlas lock once), so iterating needs no lock. Deterministic: a seeded generator draws the
// samples.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "core/geometry/pinhole_intrinsics.h"
#include "core/geometry/sim3.h"

namespace pkslam {

// One map-point pair: the same physical point as estimated in keyframe 1's and keyframe 2's
// maps (they differ by the drift the loop will correct), and its keypoints.
struct Sim3Match {
  Eigen::Vector3d point1 = Eigen::Vector3d::Zero();  // in camera 1 (camera1_from_world * X1)
  Eigen::Vector3d point2 = Eigen::Vector3d::Zero();  // in camera 2 (camera2_from_world * X2)
  Eigen::Vector2d uv1 = Eigen::Vector2d::Zero();     // undistorted keypoint in keyframe 1
  Eigen::Vector2d uv2 = Eigen::Vector2d::Zero();     // undistorted keypoint in keyframe 2
  double sigma2_1 = 1;                               // keypoint variance (octave) in 1
  double sigma2_2 = 1;                               // and in 2
  int index1 = -1;                                   // keypoint index in keyframe 1
  int index2 = -1;                                   // keypoint index in keyframe 2
};

// Closed-form least-squares similarity target ~= s R source + t (Umeyama; Horn's solution in
// matrix form). fix_scale forces s = 1. nullopt for fewer than 3 pairs or (near-)collinear
// sources, where the rotation is undetermined.
std::optional<Sim3d> AlignPoints(const std::vector<Eigen::Vector3d>& source,
                                 const std::vector<Eigen::Vector3d>& target, bool fix_scale);

struct Sim3SolverOptions {
  // Scale fixed to 1 (stereo/RGB-D): an SE(3) is estimated.
  bool fix_scale = false;
  // RANSAC confidence that decides the number of iterations from min_inliers / matches.
  double probability = 0.99;
  // A hypothesis is accepted with at least this many inliers (ORB-SLAM3's loop closing: 20).
  int min_inliers = 20;
  // Cap on iterations over all Iterate() calls (ORB-SLAM3: 300).
  int max_iterations = 300;
  // Inlier test: squared reprojection error < chi2 * sigma^2 in both images (2 DoF, 99%).
  double chi2 = 9.21;
  // Re-estimate an accepted hypothesis from all its inliers (kept only if it has at least as
  // many inliers). ORB-SLAM returns the minimal-sample model.
  bool refine = true;
  std::uint64_t seed = 0;

  void Check() const;
};

struct Sim3RansacResult {
  bool found = false;      // a hypothesis reached min_inliers in this call
  bool exhausted = false;  // the iteration budget is used up (ORB-SLAM's bNoMore)
  Sim3d camera1_from_camera2;
  std::vector<bool> inliers;  // per match (empty unless found)
  int num_inliers = 0;
};

class Sim3Solver {
 public:
  Sim3Solver(std::vector<Sim3Match> matches, const PinholeIntrinsics& camera1,
             const PinholeIntrinsics& camera2, const Sim3SolverOptions& options);

  // Runs up to `iterations` more hypotheses (never beyond the budget) and returns as soon as
  // one reaches min_inliers, so callers can interleave several candidates (ORB-SLAM's
  // iterate(5, ...)).
  Sim3RansacResult Iterate(int iterations);

  // Inlier mask and count of a model under the options' test.
  int CountInliers(const Sim3d& camera1_from_camera2, std::vector<bool>* inliers) const;

  const std::vector<Sim3Match>& matches() const { return matches_; }
  int iterations_done() const { return iterations_done_; }
  // The budget: min(max_iterations, iterations RANSAC needs for `probability`).
  int iteration_budget() const { return budget_; }
  // Best hypothesis so far (also below min_inliers), if any.
  const std::optional<Sim3d>& best() const { return best_; }
  int best_inliers() const { return best_inliers_; }

 private:
  std::vector<Sim3Match> matches_;
  PinholeIntrinsics camera1_;
  PinholeIntrinsics camera2_;
  Sim3SolverOptions options_;
  std::mt19937_64 rng_;
  int budget_ = 0;
  int iterations_done_ = 0;
  std::optional<Sim3d> best_;
  int best_inliers_ = -1;
};

}  // namespace pkslam
