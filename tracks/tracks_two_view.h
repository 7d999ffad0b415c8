// Map initialisation from two frames of tracks, the thesis's way (seed 002): RANSAC
// fundamental matrix -> E = K^T F K -> SVD -> the four [R | +-u3] candidates -> cheirality
// (points in front of both cameras) -> linear triangulation. The geometry is
// estimators/two_view (shared with the SLAM's monocular initialiser); this file adds the
// acceptance rules and the automatic choice of an initial pair with enough baseline, the fix
// the thesis proposes for its ~200 px errors after initialising from two nearby frames.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/geometry/pinhole_intrinsics.h"
#include "core/geometry/se3.h"
#include "tracks/track_index.h"

namespace pkslam {

struct TracksTwoViewOptions {
  // Pixel noise sigma of the chi2 gates (RANSAC, cheirality reprojection test).
  double sigma = 1.0;
  int ransac_iterations = 300;
  // A pair is accepted with at least `min_points` triangulated points and, when `strict`, when
  // the best candidate triangulates at least `min_good_share` of the F inliers and no other
  // candidate reaches `max_ambiguity` of its support. The thesis's original rule is not
  // strict: the candidate that puts the points in front of both cameras wins, however weakly.
  bool strict = true;
  double min_good_share = 0.9;
  double max_ambiguity = 0.7;
  int min_points = 30;
  // Baseline test of the automatic pair choice: the median ray angle (degrees) of the
  // triangulated points. 0 accepts any pair (the thesis's original first-two-frames rule).
  double min_parallax_deg = 0;
  std::uint64_t seed = 1;

  void Check() const;
};

struct TracksTwoViewResult {
  bool ok = false;
  std::string failure;  // why not, when !ok
  SE3d camera2_from_camera1;
  std::vector<int> tracks;                      // dense track ids seen in both frames
  std::vector<Eigen::Vector3d> points_camera1;  // per entry of tracks
  std::vector<bool> triangulated;               // per entry: passed cheirality + reprojection
  int num_inliers = 0;                          // of the fundamental matrix
  int num_triangulated = 0;
  double median_parallax_deg = 0;
  std::array<int, 4> candidate_good{};  // triangulated points per [R|t] candidate
  int best_candidate = -1;
};

TracksTwoViewResult ReconstructTwoViewTracks(const std::vector<IndexedObservation>& first,
                                             const std::vector<IndexedObservation>& second,
                                             const PinholeIntrinsics& camera,
                                             const TracksTwoViewOptions& options);

}  // namespace pkslam
