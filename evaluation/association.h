// Timestamp association between a reference (ground truth) and an estimated trajectory.
//
// The rule is evo's nearest-time association (evo.core.sync.associate_trajectories with
// matching_time_indices): the trajectory with fewer poses drives (the estimate when both have
// equally many); each of its stamps is paired with the nearest stamp of the other trajectory
// (the earlier one on a tie) when the two differ by at most max_diff. The offset is added to the
// estimate's stamps before comparing, like evo's --t_offset.
//
// evo's rule can pair one pose of the longer trajectory with several poses of the shorter one
// (only when the shorter trajectory has stamps less than 2 * max_diff apart). With
// one_to_one (the default) each such group keeps only its closest pair (the earliest on a tie),
// so every pose appears in at most one pair (repeats of one stamp aside, see below); whenever
// evo's pairs are already one-to-one,
// which is the usual case (e.g. a 20-30 Hz estimate against ground truth with max_diff 10 ms),
// both modes give evo's pairs exactly.
//
// Times are compared like evo does, as differences of double-precision seconds (each stamp as
// the double nearest to its exact value, which is what numpy reads from the decimal text), so
// exact ties and differences of exactly max_diff resolve as in evo. This matters on real data:
// in TUM fr2_desk an ORB stamp lies exactly halfway between two ground-truth stamps and evo's
// rounding picks the later one, which moves the published sse in its 6th digit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pkslam {

struct AssociationOptions {
  // Largest accepted |t_est + offset - t_ref| (s); evo's --t_max_diff.
  double max_diff_s = 0.01;
  // Added to every estimate timestamp before matching (s); evo's --t_offset.
  double offset_s = 0.0;
  // Drop repeated uses of a pose (see above); false reproduces evo including its repeats.
  bool one_to_one = true;

  void Check() const;
};

struct IndexPair {
  std::size_t ref = 0;  // index into the reference trajectory
  std::size_t est = 0;  // index into the estimated trajectory
  bool operator==(const IndexPair&) const = default;
};

// Pairs sorted by time (both indices non-decreasing). Both stamp lists must be sorted; repeated
// stamps are evaluated as evo does: in the driving trajectory each repeat is its own pair (also
// with one_to_one), in the other one the nearest-time search takes the first of them.
std::vector<IndexPair> AssociateTimestamps(std::span<const std::int64_t> ref_t_ns,
                                           std::span<const std::int64_t> est_t_ns,
                                           const AssociationOptions& options);

}  // namespace pkslam
