// Two-view model estimation for monocular initialisation: Hartley normalisation, the DLT
// homography and the rank-2 eight-point fundamental matrix from minimal sets, and their
// scoring by symmetric transfer error with chi2 gates (ORB-SLAM's CheckHomography /
// CheckFundamental), plus the RANSAC loop over pre-drawn minimal sets.
// Pure functions of their inputs; safe to call from several threads at once.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace pkslam::two_view {

// Size of a minimal set (both models are fitted from eight correspondences).
inline constexpr int kMinimalSetSize = 8;
using MinimalSet = std::array<int, kMinimalSetSize>;

// Corresponding pixel positions (undistorted): first[k] <-> second[k].
struct Correspondences {
  std::vector<Eigen::Vector2d> first;
  std::vector<Eigen::Vector2d> second;
  int size() const { return static_cast<int>(first.size()); }
};

// Hartley normalisation: translate the centroid to the origin and scale isotropically so the
// mean distance to it is sqrt(2). normalized[k] = T * [p; 1].
struct NormalizedPoints {
  std::vector<Eigen::Vector2d> points;
  Eigen::Matrix3d transform = Eigen::Matrix3d::Identity();
};
NormalizedPoints NormalizePoints(const std::vector<Eigen::Vector2d>& points);

// Homography H with p2 ~ H p1 from >= 4 correspondences (DLT, smallest singular vector),
// scaled to unit Frobenius norm. Feed it normalised points.
Eigen::Matrix3d ComputeHomographyDlt(const std::vector<Eigen::Vector2d>& p1,
                                     const std::vector<Eigen::Vector2d>& p2);

// Fundamental matrix F with p2^T F p1 = 0 from >= 8 correspondences (linear eight-point,
// then the closest rank-2 matrix). Feed it normalised points.
Eigen::Matrix3d ComputeFundamentalEightPoint(const std::vector<Eigen::Vector2d>& p1,
                                             const std::vector<Eigen::Vector2d>& p2);

// chi2 gates (95%): 2 DoF for a point-to-point transfer, 1 DoF for a point-to-line distance.
inline constexpr double kChi2TwoDof = 5.991;
inline constexpr double kChi2OneDof = 3.841;
// 99% gates.
inline constexpr double kChi2OneDof99 = 6.635;
inline constexpr double kChi2TwoDof99 = 9.210;

// Non-minimal re-fits on the correspondences flagged in `inliers` (normalised points), for
// local optimisation. Each equation is weighted with the current model so the linear
// least squares approximates geometric error: the homography's rows by 1 / (h3 . p1) (the
// transfer error in the second image), the fundamental matrix's by the inverse Sampson
// gradient norm. Results have unit Frobenius norm; F has rank 2.
Eigen::Matrix3d RefineHomography(const std::vector<Eigen::Vector2d>& p1,
                                 const std::vector<Eigen::Vector2d>& p2,
                                 const std::vector<std::uint8_t>& inliers,
                                 const Eigen::Matrix3d& h21);
Eigen::Matrix3d RefineFundamental(const std::vector<Eigen::Vector2d>& p1,
                                  const std::vector<Eigen::Vector2d>& p2,
                                  const std::vector<std::uint8_t>& inliers,
                                  const Eigen::Matrix3d& f21);

// Share of the correspondences flagged in `mask` that H21 transfers within the 99% 2-DoF gate
// in both directions (pixels). Near 1 for F's inliers means F is homography-degenerate.
double HomographyShare(const Eigen::Matrix3d& h21, const Correspondences& c,
                       const std::vector<std::uint8_t>& mask, double sigma);

// Score of H21 (p2 ~ H21 p1; h12 = its inverse) over all correspondences: per direction
// whose squared transfer error / sigma^2 = chi2 passes kChi2TwoDof, add kChi2TwoDof - chi2.
// A correspondence is an inlier if both directions pass. inliers is resized to the count.
double ScoreHomography(const Eigen::Matrix3d& h21, const Eigen::Matrix3d& h12,
                       const Correspondences& c, double sigma, std::vector<std::uint8_t>* inliers);

// Score of F21 (p2^T F21 p1 = 0): per direction whose squared point-to-epipolar-line
// distance / sigma^2 = chi2 passes kChi2OneDof, add kChi2TwoDof - chi2 (the same score scale
// as the homography, so the two are comparable). Inlier if both directions pass.
double ScoreFundamental(const Eigen::Matrix3d& f21, const Correspondences& c, double sigma,
                        std::vector<std::uint8_t>* inliers);

// `iterations` sets of eight distinct correspondence indices in [0, n) (n >= 8), drawn from a
// std::mt19937_64 seeded with `seed` without std::uniform_int_distribution, so the sets are
// the same with every standard library.
std::vector<MinimalSet> DrawMinimalSets(int n, int iterations, std::uint64_t seed);

struct ModelFit {
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Zero();  // in pixel coordinates (H21 or F21)
  double score = 0;                                  // 0 when no sample gave a usable model
  std::vector<std::uint8_t> inliers;                 // per correspondence
  int num_inliers = 0;
  int degenerate_samples = 0;  // F: samples skipped as homography-degenerate
  int refinements = 0;         // local-optimisation re-fits that improved the model
};

struct RansacOptions {
  // Keypoint sigma (pixels) of the chi2 gates.
  double sigma = 1.0;
  // Local optimisation (LO-RANSAC): whenever a minimal set scores better than all earlier
  // ones, re-fit its model on all its inliers (RefineHomography / RefineFundamental) and keep
  // the re-fit while the score improves, at most this many times. 0 = plain RANSAC as in
  // ORB-SLAM.
  int refine_iterations = 0;
  // F only: skip samples whose eight points are all consistent with the homography fitted to
  // them (coplanar or no parallax: the eight-point system is then rank-deficient and any
  // F = [e']x H fits the plane, so the sample says nothing about the epipole).
  bool reject_degenerate_samples = false;
};

// RANSAC over the given minimal sets (indices into c): fit on the normalised points, map
// back to pixels, score, keep the best (first best on ties). normalized1/2 come from
// NormalizePoints(c.first / c.second).
ModelFit RansacHomography(const Correspondences& c, const NormalizedPoints& normalized1,
                          const NormalizedPoints& normalized2, const std::vector<MinimalSet>& sets,
                          const RansacOptions& options);
ModelFit RansacFundamental(const Correspondences& c, const NormalizedPoints& normalized1,
                           const NormalizedPoints& normalized2, const std::vector<MinimalSet>& sets,
                           const RansacOptions& options);

}  // namespace pkslam::two_view
