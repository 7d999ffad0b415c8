// Relative error over sub-trajectories of fixed path length, as rpg_trajectory_evaluation
// computes it (Zhang & Scaramuzza, "A Tutorial on Quantitative Trajectory Evaluation for
// Visual(-Inertial) Odometry", IROS 2018), the numbers behind its box plots:
//   - path length D_k is accumulated along the reference (ground-truth) positions of the
//     associated pairs;
//   - for a segment length L every pose i starts a pair whose end j >= i is the pose with
//     |D_j - D_i - L| smallest (the first one on a tie), kept when that is below
//     max_length_difference * L (rpg: 0.2 L);
//   - the pair's error is E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j), Q the reference and P the aligned
//     estimate (a Sim(3) alignment has scaled P's positions, as rpg scales the estimate's
//     relative motion); translation error |t(E)| in m and in % of L, rotation error the angle
//     of R(E) in deg (and per metre of L); yaw and gravity errors from E expressed in the
//     world (R_j E R_j^T with R_j the aligned estimate's orientation at j), decomposed as
//     Rz(yaw) Ry(pitch) Rx(roll): |yaw| and sqrt(pitch^2 + roll^2) in deg.
//   rpg rotates E with the unaligned estimate's orientation; with the aligned one the yaw and
//   gravity split refers to the reference's world (gravity along its z), which is what the
//   two numbers are meant to separate. Translation and rotation errors are the same either way.
// Default lengths are rpg's: 10, 20, 30, 40 and 50% of the whole reference trajectory's path
// (the ground-truth file's, not only its matched poses': a 200 Hz truth is longer than its
// 20 Hz matches by its jitter), truncated to cm.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/geometry/se3.h"
#include "evaluation/rpe.h"
#include "evaluation/statistics.h"

namespace pkslam {

struct SegmentErrorOptions {
  // Segment lengths (m); empty: `fractions` of the reference path's length.
  std::vector<double> lengths_m;
  std::vector<double> fractions = {0.1, 0.2, 0.3, 0.4, 0.5};
  // The path the fractions refer to (m); 0: the matched reference poses' path.
  double reference_path_m = 0.0;
  // Accepted |path - L| as a fraction of L (rpg's max_dist_diff = 0.2 L).
  double max_length_difference = 0.2;

  void Check() const;  // throws OptionError
};

struct SegmentErrors {
  double length_m = 0.0;
  std::vector<PosePairIndices> pairs;  // indices into the associated pose lists
  std::vector<double> translation_m;
  std::vector<double> translation_percent;
  std::vector<double> rotation_deg;
  std::vector<double> rotation_deg_per_m;
  std::vector<double> yaw_deg;
  std::vector<double> gravity_deg;
  // Filled when there is at least one pair.
  ErrorStatistics translation_m_stats;
  ErrorStatistics translation_percent_stats;
  ErrorStatistics rotation_deg_stats;

  bool empty() const { return pairs.empty(); }
};

// The path length at each position: 0 at the first, then the sum of the steps.
std::vector<double> AccumulatedPathLength(const std::vector<Eigen::Vector3d>& positions);

// rpg's lengths: each fraction of `path_length_m`, truncated to two decimals.
std::vector<double> DefaultSegmentLengths(double path_length_m,
                                          const std::vector<double>& fractions);

// For each start i, the end j as described above, or none; pairs in order of i.
std::vector<PosePairIndices> SelectSegmentPairs(const std::vector<double>& accumulated_m,
                                                double length_m, double max_length_difference);

// One entry per length (options.lengths_m, or the defaults from reference_path_m); a length
// longer than the trajectory gives an entry without pairs. ref[k] and est[k] are associated
// world_from_sensor poses, est already aligned.
std::vector<SegmentErrors> ComputeSegmentErrors(const std::vector<SE3d>& ref,
                                                const std::vector<SE3d>& est,
                                                const SegmentErrorOptions& options);

}  // namespace pkslam
