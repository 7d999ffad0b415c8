// Local bundle adjustment (ORB-SLAM's LocalBundleAdjustment) split in three phases so the
// solver runs without holding the Atlas lock:
//   Collect (shared lock) -> Solve (no lock, abortable) -> Apply (exclusive lock).
// Local keyframes = the keyframe and its covisibles; local points = their points; fixed
// keyframes = other keyframes observing local points. Schur-complement solver in Ceres.
#pragma once

#include <atomic>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "core/geometry/se3.h"
#include "core/map/ids.h"

namespace pkslam {

struct BundleAdjustmentOptions {
  // Iterations of the first (robust) pass and of the second pass after outlier removal.
  int iterations_first = 5;
  int iterations_second = 10;
  // chi2 thresholds for dropping observations (monocular / stereo).
  double chi2_mono = 5.991;
  double chi2_stereo = 7.815;
  // Ceres threads (1 in deterministic mode).
  int num_threads = 1;
  // Cap on local keyframes (covisibles ordered by weight); 0 = no cap.
  int max_local_keyframes = 0;

  void Check() const;
};

// An immutable copy of what the solver needs; ids tie results back to the map.
struct LocalBundleProblem {
  struct KeyFrameState {
    KeyFramePtr keyframe;
    SE3d camera_from_world;
    bool fixed = false;
  };
  struct PointState {
    MapPointPtr point;
    Eigen::Vector3d position_world;
  };
  struct ObservationState {
    int keyframe_index;  // into keyframes
    int point_index;     // into points
    int keypoint_index;  // in the keyframe
    Eigen::Vector2d uv;  // undistorted pixel
    double u_right;      // < 0 for monocular observations
    double inv_sigma2;   // by octave
  };
  std::vector<KeyFrameState> keyframes;
  std::vector<PointState> points;
  std::vector<ObservationState> observations;
};

struct LocalBundleResult {
  std::vector<SE3d> camera_from_world;        // per problem keyframe
  std::vector<Eigen::Vector3d> points_world;  // per problem point
  std::vector<int> outlier_observations;      // indices into problem observations
  bool aborted = false;                       // aborted before the second pass
  int iterations = 0;
};

// Requires the Atlas mutex (shared). Returns an empty problem if nothing to optimise.
LocalBundleProblem CollectLocalBundle(KeyFrame* keyframe, const BundleAdjustmentOptions& options);
// Pure computation; `abort` (may be null) is polled between iterations.
LocalBundleResult SolveLocalBundle(const LocalBundleProblem& problem,
                                   const BundleAdjustmentOptions& options,
                                   const std::atomic<bool>* abort);
// Requires the Atlas mutex (exclusive): erases outlier observations, writes poses and
// positions of keyframes/points that are still live, updates normals/depth ranges.
void ApplyLocalBundle(const LocalBundleProblem& problem, const LocalBundleResult& result);

}  // namespace pkslam
