// Visual-inertial bundle adjustment (ORB-SLAM3's LocalInertialBA and FullInertialBA) in Ceres:
// the problem and result values and the solve. The map side (collecting a problem from the
// keyframe chain, applying the result) is map_model/estimation/inertial_bundle_collect.h; the
// phases are those of estimators/optim/bundle_adjustment.h, so the solve runs without the Atlas
// lock.
//
// States are body poses world_from_body (BodyPoseManifold), velocities and biases; the visual
// part (points, observations, outlier handling) is a BundleProblem whose keyframe poses are
// converted through the rig's body_from_camera. Inertial edges (imu/imu_factors.h) join
// consecutive keyframes of the map's temporal chain (KeyFrame::imu.previous()).
//
// Local window: the newest `window` keyframes of the chain ending at the new keyframe are free
// (pose, velocity, biases with random walks); the keyframe just before the window, the anchor,
// is joined by its inertial edge. With `marginalization_prior` and a valid prior on the anchor
// (estimators/inertial/marginalization.h) the anchor is free and carries that 15-D Gaussian prior:
// the information of the states that left the window (accumulated bias information in
// particular) is kept. Without a prior it is fixed at its estimate (ORB-SLAM3's choice). Either
// way the solve marginalises the anchor onto the next chain keyframe and Apply stores the result
// as that keyframe's prior, used when it becomes the anchor. Other keyframes observing the
// window's points are fixed, visual only. Full: every chain keyframe, the first pose fixed;
// optionally one bias pair shared by all with zero-mean priors (the BA right after the
// inertial-only initialisation). Full with a free tilt (estimators/inertial/gravity_gauge.h): the
// first pose carries a position + yaw gauge prior instead, so roll and pitch of the whole map
// (the gravity direction) are estimated; keyframes off the chain are then free, visual only.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/imu/imu_types.h"
#include "core/imu/inertial_state.h"
#include "estimators/optim/bundle_adjustment.h"

namespace pkslam {

struct InertialBundleOptions {
  // Free keyframes of the local window (ORB-SLAM3: 10).
  int window = 10;
  // Local window: at most this many fixed visual-only keyframes (most shared points first).
  int max_fixed_keyframes = 15;
  // Solver passes as BundleAdjustmentOptions: a robust (Huber) pass, then, if
  // iterations_second > 0, a refinement without the outliers. 0 is ORB-SLAM3's local inertial
  // BA: one robust pass whose outliers are only classified (half the Ceres set-up cost).
  int iterations_first = 8;
  int iterations_second = 0;
  double chi2_mono = 5.991;
  double chi2_stereo = 7.815;
  int num_threads = 1;
  double gravity_magnitude = 9.81;
  // Local window: keep a marginalisation prior on the anchor instead of fixing it (see above).
  bool marginalization_prior = true;
  // Eigenvalues of the marginalised anchor block below this share of its largest are treated as
  // unobservable (pseudo-inverse) when the prior is computed.
  double marginalization_threshold = 1e-12;
  // Weight (0, 1] of the anchor's reprojection factors in the marginalisation. They are
  // evaluated with the points held fixed, and the marginalised keyframe's observations keep
  // constraining the points of later windows as a fixed keyframe: < 1 discounts that
  // over-confidence (0.1 measured no better than 1 on the simulated EuRoC replays).
  double marginalization_visual_weight = 1.0;

  void Check() const;
};

struct InertialBundleProblem {
  BundleProblem visual;
  // Per visual.keyframes entry: whether it has inertial blocks, and their initial values.
  std::vector<std::uint8_t> inertial;
  std::vector<Eigen::Vector3d> velocities;
  std::vector<ImuBias> biases;
  // Preintegration between consecutive chain keyframes (indices into visual.keyframes).
  struct Edge {
    int from = -1;
    int to = -1;
    PreintegratedImu preintegration;  // without its steps
  };
  std::vector<Edge> edges;
  SE3d camera_from_body;
  Eigen::Vector3d gravity_world = Eigen::Vector3d(0, 0, -9.81);
  // One gyro and one accel bias block for every keyframe, with zero-mean priors of these
  // informations (0: none); otherwise per-keyframe biases joined by random walks.
  bool shared_bias = false;
  double gyro_prior_information = 0;
  double accel_prior_information = 0;
  // Local window with marginalisation: the prior of the anchor (keyframe 0), which is then free;
  // and the anchor -> next keyframe pair whose marginal Solve computes (-1: none), with the map
  // stamps at collection (Apply stores the prior only if they still hold). A full BA with a
  // free tilt puts its gauge prior here (marginalize_from = 0, marginalize_to = -1).
  std::optional<InertialStatePrior> anchor_prior;
  int marginalize_from = -1;
  int marginalize_to = -1;
  InertialStatePrior stamps;

  bool empty() const { return visual.keyframes.empty(); }
};

struct InertialBundleResult {
  BundleResult visual;
  std::vector<Eigen::Vector3d> velocities;  // per visual.keyframes entry
  std::vector<ImuBias> biases;
  // The prior of keyframe problem.marginalize_to (Solve computes it when requested; stamps as
  // problem.stamps).
  std::optional<InertialStatePrior> next_prior;
};

// Pure computation; `abort` (may be null) is polled between iterations; `work` (may be null)
// counts the residual evaluations as they happen (core/util/work_meter.h).
InertialBundleResult SolveInertialBundle(const InertialBundleProblem& problem,
                                         const InertialBundleOptions& options,
                                         const std::atomic<bool>* abort = nullptr,
                                         WorkMeter* work = nullptr);
}  // namespace pkslam
