// KITTI odometry's error metric, as the benchmark's devkit (evaluate_odometry.cpp) computes it:
//   - path length D_k accumulated along the ground-truth positions;
//   - every step-th frame (10: one second at 10 Hz) starts a segment for each length L of
//     100, 200, ..., 800 m; it ends at the first frame whose D exceeds D_start + L (no segment
//     when the sequence ends first);
//   - error E = (P_s^-1 P_e)^-1 (Q_s^-1 Q_e), P the estimate and Q the truth; translation error
//     |t(E)| / L and rotation error acos(clamp((tr R(E) - 1) / 2)) / L;
//   - the sequence's numbers are the means over all segments: translation in % (x 100) and
//     rotation in deg per 100 m; per length the same means over that length's segments.
// The devkit pairs poses by frame index (every frame has a pose). Here index k is the k-th
// associated pose pair, so a run with a pose for every frame gets the devkit's numbers; one that
// lost frames is measured on the frames it has.
#pragma once

#include <vector>

#include "core/geometry/se3.h"

namespace pkslam {

struct KittiErrorOptions {
  std::vector<double> lengths_m = {100, 200, 300, 400, 500, 600, 700, 800};
  int step_frames = 10;

  void Check() const;  // throws OptionError
};

struct KittiSegmentError {
  std::size_t first = 0, last = 0;  // pose indices
  double length_m = 0;
  double translation_per_m = 0;   // |t(E)| / L
  double rotation_rad_per_m = 0;  // angle(E) / L
};

struct KittiErrors {
  std::vector<KittiSegmentError> segments;
  double translation_percent = 0;    // mean over segments x 100
  double rotation_deg_per_100m = 0;  // mean over segments, deg per 100 m
  struct PerLength {
    double length_m = 0;
    std::size_t segments = 0;
    double translation_percent = 0;
    double rotation_deg_per_100m = 0;
  };
  std::vector<PerLength> per_length;  // lengths without a segment are left out
  bool empty() const { return segments.empty(); }
};

// ref[k] and est[k] are associated world_from_camera poses (est may be aligned: the metric is
// invariant to a rigid alignment, and a Sim(3) one scales it as the devkit's users do).
KittiErrors ComputeKittiErrors(const std::vector<SE3d>& ref, const std::vector<SE3d>& est,
                               const KittiErrorOptions& options = {});

}  // namespace pkslam
