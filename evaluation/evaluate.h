// Trajectory evaluation: associate by time, align, then absolute (ATE) and relative (RPE)
// errors, reproducing evo_ape / evo_rpe (see association.h, alignment.h, rpe.h for the rules).
//
// ATE translation error of pair k: |p_ref_k - T p_est_k| with T = ref_from_est (evo_ape's
// trans_part); ATE rotation error: the angle of R_ref_k^T (R_T R_est_k) in degrees (evo_ape's
// angle_deg). A sim3 alignment also scales the estimate's positions before RPE, as evo does.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/geometry/sim3.h"
#include "core/util/json_writer.h"
#include "evaluation/alignment.h"
#include "evaluation/association.h"
#include "evaluation/kitti_error.h"
#include "evaluation/rpe.h"
#include "evaluation/segment_error.h"
#include "evaluation/statistics.h"
#include "io/trajectory.h"

namespace pkslam {

struct EvaluationOptions {
  // How estimate poses are paired with reference poses.
  AssociationOptions association;
  // How the estimate is aligned to the reference before measuring errors.
  AlignmentMethod alignment = AlignmentMethod::kSE3;
  // Whether to compute the RPE, and how.
  bool compute_rpe = true;
  RpeOptions rpe;
  // Relative error over sub-trajectory lengths, as rpg_trajectory_evaluation (segment_error.h).
  bool compute_segments = false;
  SegmentErrorOptions segments;
  // KITTI odometry's metric (kitti_error.h: translation % and deg per 100 m over 100-800 m).
  bool compute_kitti = false;
  KittiErrorOptions kitti;
  // Measure even when the aligned estimate's orientation differs from the reference's by a
  // near-constant rotation (CheckSameBodyFrame): by default that is an error, since it means
  // the two trajectories describe different frames (a camera against body ground truth).
  bool allow_frame_offset = false;

  void Check() const;
};

struct EvaluationResult {
  std::size_t ref_poses = 0;  // poses in the reference trajectory
  std::size_t est_poses = 0;  // poses in the estimated trajectory
  std::vector<IndexPair> pairs;
  AlignmentMethod alignment = AlignmentMethod::kSE3;
  Sim3d ref_from_est;  // the alignment applied to the estimate (identity for none)
  std::vector<double> ate_translation_errors_m;  // one per pair
  std::vector<double> ate_rotation_errors_deg;   // one per pair
  ErrorStatistics ate_translation_m;
  ErrorStatistics ate_rotation_deg;
  std::optional<RpeResult> rpe;  // when options.compute_rpe
  // When options.compute_segments: one entry per segment length (some may have no pairs).
  std::optional<std::vector<SegmentErrors>> segments;
  std::optional<KittiErrors> kitti;  // when options.compute_kitti
  // The associated poses, pair k of each: the reference's, and the estimate's after alignment
  // (what the errors above compare; for saving and plotting).
  std::vector<SE3d> matched_ref;
  std::vector<SE3d> aligned_est;
  EvaluationOptions options;  // as used

  double scale() const { return ref_from_est.scale(); }
};

// Throws InputError naming the estimate's file when no pose pair falls within max_diff (the
// message gives both time ranges), when there are too few pairs for the alignment, when a
// matched pose is not finite, when for a Sim(3) alignment either side's matched positions do not
// move (identical or all-zero poses once gave a scale of 2.44 and an ATE as if valid),
// or when the aligned orientations differ by a near-constant rotation of more than 5 degrees
// on a path that is not a straight line (see allow_frame_offset); OptionError for bad options.
EvaluationResult EvaluateTrajectories(const Trajectory& ref, const Trajectory& est,
                                      const EvaluationOptions& options);

// The result as one JSON object: {"pairs", "gt_poses", "est_poses", "max_diff_s",
// "alignment", "scale", "ate": stats, "ate_rot_deg": stats, "rpe": {"delta", "unit",
// "all_pairs", "pairs", "trans_m": stats, "rot_deg": stats} or null, "segments": [{"length_m",
// "pairs", "trans_m", "trans_percent", "rot_deg": stats or null}] or null, "kitti":
// {"segments", "trans_percent", "rot_deg_per_100m", "per_length": [...]} or null}; stats = {"rmse",
// "mean", "median", "std", "min", "max", "sse"}.
void WriteEvaluationJson(const EvaluationResult& result, JsonWriter& json);
std::string EvaluationJson(const EvaluationResult& result);

// A readable multi-line table of the same numbers.
std::string FormatEvaluationTable(const EvaluationResult& result);

// The segment errors' medians, one line per length (part of FormatEvaluationTable).
std::string FormatSegmentTable(const std::vector<SegmentErrors>& segments);
// KITTI's numbers and one line per length (part of FormatEvaluationTable).
std::string FormatKittiTable(const KittiErrors& kitti);

}  // namespace pkslam
