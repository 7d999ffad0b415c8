// Descriptor matching primitives of the ORB-SLAM family: search by projection, by BoW node,
// for triangulation (epipolar), for initialisation (window), fusion of duplicates, and Sim3
// guided search. All functions read the map model and therefore need the Atlas mutex held
// (shared) by the caller, except Fuse, which changes the map and takes the write lock.
#pragma once

#include <Eigen/Core>
#include <array>
#include <utility>
#include <vector>

#include "core/geometry/se3.h"
#include "core/geometry/sim3.h"
#include "map_model/frame.h"
#include "map_model/map_ids.h"

namespace pkslam {

class MapWriteLock;

// ORB-SLAM's thresholds on 256-bit Hamming distances.
inline constexpr int kOrbThHigh = 100;
inline constexpr int kOrbThLow = 50;
inline constexpr int kRotationHistogramBins = 30;

// A map point projected into a frame by the tracker's frustum test (replaces ORB-SLAM's
// mTrackProjX/... fields on MapPoint).
struct ProjectedPoint {
  MapPointPtr point;
  double u = 0;  // projected undistorted pixel
  double v = 0;
  double u_right = -1;  // projected right-image u for stereo/RGB-D (negative: none)
  int predicted_level = 0;
  double view_cos = 1;  // cosine between the viewing ray and the point's mean normal
  double depth = 0;     // depth in the frame's camera
};

// Holds only its two settings: one instance may be used from several threads at once.
class OrbMatcher {
 public:
  // nn_ratio: Lowe ratio between best and second-best distance (1 disables the test).
  // check_orientation: keep only matches whose keypoint-angle differences fall in the three
  // most populated bins of a 30-bin rotation histogram.
  explicit OrbMatcher(double nn_ratio = 0.6, bool check_orientation = true)
      : nn_ratio_(nn_ratio), check_orientation_(check_orientation) {}

  // Local-map tracking: matches projected points into the frame's empty slots (or slots holding
  // a point without observations) within a radius RadiusByViewingCos(view_cos) * th * (octave
  // scale), on the predicted level or one below; stereo candidates must agree on u_right.
  // Accepts best <= TH_HIGH unless the runner-up is on the same level and best > nn_ratio *
  // second. A slot filled by this call is not taken again by a later point.
  // far_points_th > 0 skips points deeper than it. Returns the number of new matches.
  int SearchByProjection(Frame* frame, const std::vector<ProjectedPoint>& points, double th,
                         double far_points_th = 0) const;

  // Motion-model tracking: points of last_frame (with its pose) projected into `current`
  // (whose pose is predicted). th is the base radius; `monocular` disables the forward/
  // backward octave restriction ORB-SLAM applies for stereo. Best <= TH_HIGH, no ratio test,
  // rotation check; one point per slot.
  int SearchByProjection(Frame* current, const Frame& last_frame, double th, bool monocular) const;

  // Relocalisation: points of `keyframe` not in `already_found` projected into `current`
  // (distance range, predicted scale +-1, radius th * scale, best <= orb_distance into empty
  // slots, rotation check).
  int SearchByProjection(Frame* current, const KeyFrame& keyframe,
                         const std::vector<MapPoint*>& already_found, double th,
                         int orb_distance) const;

  // Loop closing: points projected with a Sim3 camera_from_world (scaled) into `keyframe`;
  // fills matched[i] for keypoint i (entries already set are kept; an empty vector is sized
  // to the keyframe). Accepts best <= TH_LOW * ratio_hamming. Returns new matches.
  int SearchByProjection(const KeyFrame& keyframe, const Sim3d& camera_from_world,
                         const std::vector<MapPointPtr>& points, std::vector<MapPointPtr>* matched,
                         double th, double ratio_hamming) const;

  // Reference-keyframe tracking / relocalisation: matches the keyframe's map points to the
  // frame's features sharing a vocabulary node. matches[i] = map point for frame keypoint i.
  int SearchByBoW(const KeyFrame& keyframe, const Frame& frame,
                  std::vector<MapPointPtr>* matches) const;

  // Loop detection: matches12[i1] = map point of kf2 matched to keypoint i1 of kf1.
  int SearchByBoW(const KeyFrame& kf1, const KeyFrame& kf2,
                  std::vector<MapPointPtr>* matches12) const;

  // Monocular initialisation: for each keypoint of f1 (level 0 only), search f2 around
  // prev_matched[i] within window_size. matches12[i1] = i2 or -1 (one-to-one: a keypoint of
  // f2 claimed twice goes to the closer descriptor). prev_matched is updated to the matched
  // positions.
  int SearchForInitialization(const Frame& f1, const Frame& f2,
                              std::vector<cv::Point2f>* prev_matched, std::vector<int>* matches12,
                              int window_size) const;

  // Triangulation: pairs (i1, i2) of unmatched keypoints of kf1/kf2 sharing a BoW node and
  // satisfying the epipolar constraint (distance < 3.84 * sigma^2 of kf2's octave), not too
  // close to the epipole (10 * scale px, unless one side is stereo). only_stereo restricts to
  // keypoints with depth in both. One-to-one (the closer descriptor keeps a kf2 keypoint);
  // pairs are ordered by i1.
  std::vector<std::pair<int, int>> SearchForTriangulation(const KeyFrame& kf1, const KeyFrame& kf2,
                                                          bool only_stereo = false) const;

  // Fusion: projects `points` into `keyframe`; a match to an occupied slot fuses the two map
  // points (the one with more observations survives), to an empty slot adds an observation.
  // Throws without the write lock. Returns the number of fused/added points.
  int Fuse(const MapWriteLock& lock, KeyFrame* keyframe, const std::vector<MapPointPtr>& points,
           double th = 3.0) const;

  // Loop fusion with a Sim3 camera_from_world: returns, per point, the keyframe's point it
  // should be replaced by (or nullptr); adds observations for empty slots. Throws without the
  // write lock.
  // replace_with is reset to points.size() nullptrs unless it already has that size (then
  // entries are only overwritten where a replacement is found).
  int Fuse(const MapWriteLock& lock, KeyFrame* keyframe, const Sim3d& camera_from_world,
           const std::vector<MapPointPtr>& points, double th,
           std::vector<MapPointPtr>* replace_with) const;

  // Sim3-guided search between two keyframes (S12 maps kf2's camera to kf1's camera): kf1's
  // points projected into kf2 and kf2's into kf1; only pairs found both ways are kept.
  // matches12 entries already set are kept (an empty vector is sized to kf1). Returns the
  // number of new matches.
  int SearchBySim3(const KeyFrame& kf1, const KeyFrame& kf2, std::vector<MapPointPtr>* matches12,
                   const Sim3d& s12, double th) const;

  // Radius factor by viewing angle used in local-map search (ORB-SLAM's RadiusByViewingCos).
  static double RadiusByViewingCos(double view_cos) { return view_cos > 0.998 ? 2.5 : 4.0; }

  // The three most populated bins of a rotation histogram (ind2/ind3 = -1 when a bin has
  // less than 10% of the first).
  static std::array<int, 3> ThreeMaxima(const std::vector<std::vector<int>>& histogram);

 private:
  // Lowe's test as ORB-SLAM applies it in BoW / initialisation searches (strict), off at 1.
  bool PassesRatio(int best, int second) const {
    return nn_ratio_ >= 1.0 || best < nn_ratio_ * second;
  }

  double nn_ratio_;
  bool check_orientation_;
};

}  // namespace pkslam
