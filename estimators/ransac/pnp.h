// Absolute pose (PnP) RANSAC for relocalisation, on OpenGV's solvers: Kneip's P3P (+ a fourth
// point to pick among its solutions) on minimal samples, EPnP on the inlier set and OpenGV's
// Levenberg-Marquardt refinement. Inliers are judged in pixels with a per-keypoint threshold
// chi2 * sigma^2 of the keypoint's octave, like ORB-SLAM's PnP solvers.
//
// Seeding: OpenGV's sac::Ransac draws samples from a std::mt19937 owned by the problem, seeded
// from time() unless the problem is built with randomSeed = false (then always 12345); the
// generator is a public member, so it can be re-seeded (SolvePnpOpenGvRansac does). PnpRansac
// does not use sac::Ransac at all: it draws its own samples from a seeded std::mt19937_64 and
// only calls OpenGV's solvers, which are deterministic. Both paths are reproducible bit for
// bit for a given seed. (OpenGV's AbsolutePoseSacProblem with EPNP falls through into GP3P,
// a missing `break` in OpenGV 1.0, so the minimal solver here is always KNEIP.)
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "core/geometry/pinhole_intrinsics.h"
#include "core/geometry/se3.h"

namespace pkslam {

struct PnpCorrespondence {
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // undistorted keypoint
  double sigma2 = 1;                             // keypoint variance (octave)
  Eigen::Vector3d point_world = Eigen::Vector3d::Zero();
  int index = -1;  // keypoint index in the frame (caller bookkeeping)
};

struct PnpRansacOptions {
  // RANSAC confidence for the iteration budget.
  double probability = 0.99;
  // Accept a pose with at least max(min_inliers, min_inlier_ratio * correspondences) inliers
  // (ORB-SLAM3's relocalisation: 10 and 0.5); the ratio also sets the iteration budget.
  int min_inliers = 10;
  double min_inlier_ratio = 0.5;
  // Cap on hypotheses over all Iterate() calls (ORB-SLAM3: 300).
  int max_iterations = 300;
  // Inlier test: squared reprojection error < chi2 * sigma^2 (2 DoF, 95%).
  double chi2 = 5.991;
  // EPnP on the inliers of an accepted hypothesis, then nonlinear refinement; the refined
  // pose must keep at least the acceptance count (ORB-SLAM's Refine()).
  bool refine = true;
  std::uint64_t seed = 0;

  void Check() const;
};

struct PnpResult {
  bool found = false;      // a pose reached the acceptance count in this call
  bool exhausted = false;  // the iteration budget is used up
  SE3d camera_from_world;
  std::vector<bool> inliers;  // per correspondence (empty unless found)
  int num_inliers = 0;
};

class PnpRansac {
 public:
  PnpRansac(std::vector<PnpCorrespondence> correspondences, const PinholeIntrinsics& camera,
            const PnpRansacOptions& options);
  ~PnpRansac();
  // Holds OpenGV adapters that point into its own vectors: not copyable or movable.
  PnpRansac(const PnpRansac&) = delete;
  PnpRansac& operator=(const PnpRansac&) = delete;

  // Up to `iterations` more hypotheses (within the budget); returns at the first accepted,
  // refined pose so relocalisation can interleave candidates (ORB-SLAM's iterate(5, ...)).
  PnpResult Iterate(int iterations);

  int CountInliers(const SE3d& camera_from_world, std::vector<bool>* inliers) const;
  const std::vector<PnpCorrespondence>& correspondences() const { return correspondences_; }
  int iterations_done() const { return iterations_done_; }
  int iteration_budget() const { return budget_; }
  int required_inliers() const { return required_inliers_; }

 private:
  // EPnP + nonlinear refinement on the inliers; nullopt if it loses inliers.
  std::optional<SE3d> Refine(const std::vector<bool>& inliers, int count, int* refined_count,
                             std::vector<bool>* refined_inliers) const;

  std::vector<PnpCorrespondence> correspondences_;
  PinholeIntrinsics camera_;
  PnpRansacOptions options_;
  struct OpenGv;
  std::unique_ptr<OpenGv> opengv_;
  std::mt19937_64 rng_;
  int required_inliers_ = 0;
  int budget_ = 0;
  int iterations_done_ = 0;
};

// 1 - cos(angle) of a reprojection error of `pixels` at focal length `focal` (OpenGV's
// absolute-pose RANSAC threshold).
double AngularThreshold(double pixels, double focal);

// The same problem through OpenGV's own sac::Ransac (KNEIP, RNG re-seeded with
// options.seed) with a single angular threshold of `threshold_pixels` at the mean focal
// length, then OpenGV's nonlinear refinement on the inliers. For comparison and benchmarks;
// relocalisation uses PnpRansac (per-octave thresholds, interleavable). found = at least
// options.min_inliers inliers.
PnpResult SolvePnpOpenGvRansac(const std::vector<PnpCorrespondence>& correspondences,
                               const PinholeIntrinsics& camera, double threshold_pixels,
                               const PnpRansacOptions& options);

}  // namespace pkslam
