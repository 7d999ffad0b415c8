// Geometric verification of a place-recognition candidate (ORB-SLAM3's
// DetectCommonRegionsFromBoW and DetectAndReffineSim3FromLastKF): BoW matches between the
// query keyframe and the candidate's covisibility window -> Sim3 RANSAC (SE3 when the scale is
// observable, i.e. stereo/RGB-D) -> guided projection search -> Sim3 optimisation -> a second
// projection search. A verified region is then confirmed by the query's covisible keyframes
// and, if needed, by the next keyframes (PlaceConfirmation).
//
// Threading: every function here reads the map model and needs the Atlas mutex held (shared)
// by the caller; the RANSAC and the optimisation work on copies. Nothing is written.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "core/geometry/sim3.h"
#include "map_model/map_ids.h"

namespace pkslam {

struct PlaceVerifierOptions {
  // Keyframes of the candidate's window: the candidate and its best covisibles (ORB-SLAM3: 5).
  int window_covisibles = 5;
  // Lowe ratio of the BoW search between the query and the window's keyframes.
  double bow_ratio = 0.9;
  // BoW matches needed before RANSAC (ORB-SLAM3: 20).
  int min_bow_matches = 20;
  // Sim3 RANSAC: inliers to accept a hypothesis (ORB-SLAM3: 15) and the iteration cap.
  int min_ransac_inliers = 15;
  int ransac_iterations = 300;
  // Guided search with the RANSAC model: radius (px), Hamming factor on TH_LOW, matches
  // needed (ORB-SLAM3: 8, 1.5, 50).
  double projection_radius = 8.0;
  double projection_hamming = 1.5;
  int min_projection_matches = 50;
  // Inliers of the Sim3 optimisation (ORB-SLAM3: 20).
  int min_optimised_inliers = 20;
  // Second search with the optimised model: radius, Hamming factor, matches (ORB-SLAM3: 5, 1,
  // 80).
  double refined_radius = 5.0;
  double refined_hamming = 1.0;
  int min_refined_matches = 80;
  // A keyframe near the query (covisible or the next ones) confirms the region with at least
  // this many projection matches (ORB-SLAM3: half of min_refined_matches).
  int min_confirmation_matches = 40;
  // Scale fixed to 1 (stereo, RGB-D): SE3 verification.
  bool fix_scale = true;

  void Check() const;
};

// A place seen again: the query keyframe, the keyframe it matched and what fusion needs.
struct CommonRegion {
  KeyFramePtr query;    // the keyframe that recognised the place
  KeyFramePtr matched;  // the window keyframe that carried the best BoW matches
  // Sim3 query camera_from_world expressed in the matched keyframe's world (the pose the query
  // should have to agree with the matched side).
  Sim3d query_camera_from_world;
  std::vector<KeyFramePtr> window;         // matched keyframe and its best covisibles
  std::vector<MapPointPtr> window_points;  // their good points (id order)
  // Per keypoint of the query: the window point it matches (or null).
  std::vector<MapPointPtr> matched_points;
  int matches = 0;        // non-null entries of matched_points
  int confirmations = 1;  // the query itself, its covisibles and later keyframes that agree
};

// Verifies one candidate for `query`. Returns the region when every stage passes. `seed`
// drives the RANSAC samples (deterministic).
std::optional<CommonRegion> VerifyCandidate(const KeyFramePtr& query, KeyFrame* candidate,
                                            const PlaceVerifierOptions& options,
                                            std::uint64_t seed);

// Projection matches of the region's window points into `keyframe` posed by
// keyframe_camera_from_world (Sim3, in the window's world); fills `matched` (sized to the
// keyframe) when non-null.
int CountRegionMatches(const CommonRegion& region, const KeyFrame& keyframe,
                       const Sim3d& keyframe_camera_from_world, const PlaceVerifierOptions& options,
                       std::vector<MapPointPtr>* matched);

// The pose of another keyframe of the query's map in the window's world, carried over through
// the relative motion to the region's query.
Sim3d CarryOver(const CommonRegion& region, const KeyFrame& keyframe);

// How many of the query's best `n` covisibles confirm the region.
int ConfirmByCovisibles(const CommonRegion& region, int n, const PlaceVerifierOptions& options);

}  // namespace pkslam
