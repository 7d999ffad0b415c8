// Relative pose error (RPE) over pose pairs a fixed delta apart, as evo_rpe computes it.
//
// For a pair (i, j): E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j) with Q the reference and P the (aligned)
// estimate; the translation error is |t(E)| (m) and the rotation error the angle of R(E) (deg),
// i.e. evo's `--pose_relation trans_part` and `angle_deg`. Pairs are chosen on the estimate's
// poses (evo's default; the lists must already be associated, index k of both is one pair):
//   frames, all pairs:     (i, i + delta) for every i                   (evo --all_pairs)
//   frames, consecutive:   (0, d), (d, 2d), ...                         (evo default)
//   metres, all pairs:     for every i the j found by evo's bounded binary search over the
//                          path length from i: the path i..j lies within delta +- tol * delta
//                          and is (locally) closest to delta; i without such a j is skipped
//   metres, consecutive:   evo's walk: index k is kept when the path since the previous kept
//                          index (since index 0 at the start) reaches delta; consecutive kept
//                          indices form the pairs.
// Path lengths come from prefix sums of the step lengths (evo sums each stretch afresh; they
// differ by rounding only).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string_view>
#include <utility>
#include <vector>

#include "core/geometry/se3.h"
#include "evaluation/statistics.h"

namespace pkslam {

enum class RpeUnit { kFrames, kMeters };

// "frames" or "m" (also "meters", "metres"); throws OptionError otherwise.
RpeUnit ParseRpeUnit(std::string_view name);
std::string_view RpeUnitName(RpeUnit unit);  // "frames" or "m"

struct RpeOptions {
  // Distance between the poses of a pair: a whole number of frames, or metres of path.
  double delta = 1.0;
  RpeUnit unit = RpeUnit::kFrames;
  // Every pose starts a pair (evo --all_pairs) instead of non-overlapping consecutive pairs
  // (evo's default). With the default delta of one frame both select the same pairs.
  bool all_pairs = false;
  // Metres with all pairs: accepted |path - delta| relative to delta (evo's rel_delta_tol).
  double relative_tolerance = 0.1;

  void Check() const;
};

using PosePairIndices = std::pair<std::size_t, std::size_t>;

// The pairs selected on `positions` (the estimate's) by options (see above); may be empty.
std::vector<PosePairIndices> SelectRpePairs(const std::vector<Eigen::Vector3d>& positions,
                                            const RpeOptions& options);

struct RpeResult {
  std::vector<PosePairIndices> pairs;
  std::vector<double> translation_errors_m;  // one per pair
  std::vector<double> rotation_errors_deg;   // one per pair
  ErrorStatistics translation_m;
  ErrorStatistics rotation_deg;
};

// ref[k] and est[k] are associated world_from_sensor poses (est already aligned). Throws
// OptionError when the delta selects no pair (e.g. longer than the trajectory).
RpeResult ComputeRpe(const std::vector<SE3d>& ref, const std::vector<SE3d>& est,
                     const RpeOptions& options);

}  // namespace pkslam
