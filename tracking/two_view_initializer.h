// Monocular map initialisation from two views (ORB-SLAM's Initializer / TwoViewReconstruction):
// homography and fundamental matrix estimated in parallel by RANSAC on the same minimal sets,
// scored by symmetric transfer error; the model is chosen by R_H = S_H / (S_H + S_F) > 0.50
// (ORB-SLAM3's value; ORB-SLAM2 used 0.40); the motion is recovered (H: Faugeras
// decomposition, 8 hypotheses; F: E = K^T F K, 4 hypotheses) and the hypothesis is accepted
// only if it is clearly the best by number of triangulated points in front of both cameras
// with enough parallax (ORB-SLAM's rules, see two_view_initializer.cc).
//
// Additions to ORB-SLAM, each switchable (TwoViewOptions): local optimisation of the RANSAC
// models, rejection of homography-degenerate F samples, choosing H when F is degenerate, and
// a calibrated refinement of the accepted motion. Without them ORB-SLAM's plain eight-point
// models at 1 px noise usually fail its own 90%-triangulated rule, and a planar scene never
// selects H (see the option comments).
//
// Thread-safe: no shared state; with options.parallel the homography RANSAC runs on one extra
// thread (std::async) for the duration of the call. Deterministic for a given seed.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/geometry/se3.h"
#include "map_model/frame.h"

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
  // Homography chosen when R_H = S_H / (S_H + S_F) exceeds this (ORB-SLAM3: 0.50).
  double min_homography_ratio = 0.50;
  // Run the homography and fundamental RANSAC concurrently (the result is identical).
  bool parallel = true;

  // --- additions to ORB-SLAM (0 / false / > 1 reproduce it) ---
  // LO-RANSAC: whenever a minimal set scores better than all earlier ones, re-fit its model
  // on its inliers (weighted linear least squares) while the score improves, at most this
  // many times. A minimal eight-point F at 1 px noise is a degree or more off, so that only
  // ~80% of its inliers triangulate and ORB-SLAM's 90% rule refuses it.
  int refine_iterations = 10;
  // Skip F samples whose eight points one homography explains (coplanar or no parallax: the
  // eight-point F is then undetermined).
  bool reject_degenerate_samples = true;
  // Choose H whatever R_H when the best H explains at least this share of F's inliers (99%
  // gate): F is then homography-degenerate. On a plane every F = [e']x H fits as well as H
  // and scores higher under ORB-SLAM's 1-DoF gate (expected R_H ~0.41 at noise = sigma), so
  // the 0.50 rule alone never picks H there. Values > 1 disable.
  double degenerate_f_share = 0.8;
  // Refine the accepted motion (R and the direction of t) by Levenberg-Marquardt on the
  // Sampson error of E = [t]x R (two passes: on the triangulated points, then on every match
  // within the 99% Sampson gate) and triangulate again. Uses the known intrinsics, which F
  // ignores; halves the translation-direction error (two_view_refine.h).
  bool refine_motion = true;

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
  // Number of `triangulated` keypoints.
  int num_triangulated = 0;
};

// Why a reconstruction was refused (or kNone when it succeeded).
enum class TwoViewRejection {
  kNone,
  kTooFewMatches,    // fewer matches than min_triangulated (or than a minimal set)
  kNoModel,          // neither RANSAC found a model with a positive score
  kDegenerateModel,  // homography with (nearly) repeated singular values, e.g. pure rotation
  kAmbiguous,        // no hypothesis clearly better than the others
  kTooFewGood,       // best hypothesis triangulates too few of the model's inliers
  kLowParallax,      // best hypothesis lacks parallax (small baseline / pure rotation)
};
const char* ToString(TwoViewRejection rejection);

// What the reconstruction saw (for logs, tests and the initialisation statistics).
struct TwoViewReport {
  int num_matches = 0;
  double score_homography = 0, score_fundamental = 0;
  double homography_ratio = 0;  // R_H
  double homography_share = 0;  // share of F's inliers the best H explains
  bool used_homography = false;
  int num_model_inliers = 0;                // inliers of the chosen model
  std::vector<int> hypothesis_good;         // good points per motion hypothesis
  std::vector<double> hypothesis_parallax;  // parallax (deg) per motion hypothesis
  int best_hypothesis = -1;
  // RMS Sampson error (normalised image units) of the accepted motion before refinement (on
  // its triangulated points) and after (on the 99%-gate matches); 0 when not refined.
  double sampson_rms_before = 0, sampson_rms_after = 0;
  TwoViewRejection rejection = TwoViewRejection::kNone;
};

// matches12[i1] = index of the matched keypoint in `second` or -1. Works on undistorted
// keypoints with the rig's pinhole K. nullopt when no reliable reconstruction exists.
std::optional<TwoViewResult> ReconstructTwoView(const Frame& first, const Frame& second,
                                                const std::vector<int>& matches12,
                                                const TwoViewOptions& options);
// Same, also filling *report (not null) whatever the outcome.
std::optional<TwoViewResult> ReconstructTwoView(const Frame& first, const Frame& second,
                                                const std::vector<int>& matches12,
                                                const TwoViewOptions& options,
                                                TwoViewReport* report);

}  // namespace pkslam
