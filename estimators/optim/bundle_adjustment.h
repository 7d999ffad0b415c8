// Bundle adjustment over keyframe poses and map points (ORB-SLAM's LocalBundleAdjustment and
// GlobalBundleAdjustment) in Ceres with a Schur-complement solver. This is the estimator: it
// takes a BundleProblem value and returns a BundleResult value and never sees a map object.
// The map side (map_model/estimation/bundle_collect.h) collects the problem under a shared
// lock and applies the result under the exclusive one, so the solver runs without the lock:
//   Collect (shared lock) -> Solve (no lock, abortable) -> Apply (exclusive lock).
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <vector>

#include "core/geometry/se3.h"
#include "core/util/ids.h"
#include "core/util/work_meter.h"

namespace pkslam {

struct BundleAdjustmentOptions {
  // Iterations of the first (robust, Huber) pass and of the second pass run after the
  // outlier observations are removed (0 skips the second pass).
  int iterations_first = 5;
  int iterations_second = 10;
  // chi2 thresholds for outlier observations (95%, monocular 2 DoF / stereo 3 DoF).
  double chi2_mono = 5.991;
  double chi2_stereo = 7.815;
  // Ceres threads (1 in deterministic mode).
  int num_threads = 1;
  // Local BA: cap on local keyframes (covisibles by weight); 0 = no cap.
  int max_local_keyframes = 0;

  void Check() const;
};

// An immutable copy of what the solver needs; the ids tie results back to the map.
struct BundleProblem {
  struct KeyFrameState {
    KeyFrameId keyframe_id = kInvalidId;
    SE3d camera_from_world;
    bool fixed = false;
  };
  struct PointState {
    MapPointId point_id = kInvalidId;
    Eigen::Vector3d position_world;
  };
  struct ObservationState {
    int keyframe_index;  // into keyframes
    int point_index;     // into points
    int keypoint_index;  // in the keyframe
    Eigen::Vector2d uv;  // undistorted pixel
    double u_right;      // < 0 for monocular observations
    double inv_sigma2;   // 1 / sigma^2 of the keypoint octave
    // RGB-D: information of the depth reading's disparity (reprojection_error.h); 0: stereo.
    double disparity_inv_sigma2 = 0.0;
  };
  std::vector<KeyFrameState> keyframes;
  std::vector<PointState> points;
  std::vector<ObservationState> observations;
  // Pinhole intrinsics of the (shared) rig: fx, fy, cx, cy, bf.
  double fx = 0, fy = 0, cx = 0, cy = 0, bf = 0;
  // The map the problem was collected from (kInvalidId for hand-made problems).
  MapId map_id = kInvalidId;

  bool empty() const { return observations.empty(); }
};

struct BundleResult {
  std::vector<SE3d> camera_from_world;        // per problem keyframe
  std::vector<Eigen::Vector3d> points_world;  // per problem point
  std::vector<int> outlier_observations;      // indices into problem observations
  bool aborted = false;                       // stopped before finishing
  int iterations = 0;
  double initial_cost = 0;
  double final_cost = 0;
};

// Pure computation; `abort` (may be null) is polled between iterations; `work` (may be null)
// counts the residual evaluations as they happen (core/util/work_meter.h).
BundleResult SolveBundle(const BundleProblem& problem, const BundleAdjustmentOptions& options,
                         const std::atomic<bool>* abort = nullptr, WorkMeter* work = nullptr);
}  // namespace pkslam
