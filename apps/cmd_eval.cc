// pkslam eval: ATE/RPE of an estimated trajectory against ground truth (evo-compatible).
#include <fmt/format.h>

#include <fstream>
#include <iostream>
#include <memory>
#include <string>

#include "apps/commands.h"
#include "core/util/error.h"
#include "core/util/output_file.h"
#include "evaluation/evaluate.h"
#include "io/rigid_transform_file.h"
#include "io/trajectory.h"

namespace pkslam::apps {
namespace {

struct EvalArgs {
  std::string gt_file;
  std::string est_file;
  std::string gt_format = "auto";
  std::string est_format = "auto";
  std::string align = "se3";
  double max_diff_s = 0.01;
  double offset_s = 0.0;
  bool evo_association = false;
  double rpe_delta = 1.0;
  std::string rpe_unit = "frames";
  bool rpe_consecutive = false;
  std::string json_file;
  std::string body_from_camera_file;
  bool allow_frame_offset = false;
};

void RunEval(const EvalArgs& args) {
  EvaluationOptions options;
  options.alignment = ParseAlignmentMethod(args.align);
  options.association.max_diff_s = args.max_diff_s;
  options.association.offset_s = args.offset_s;
  options.association.one_to_one = !args.evo_association;
  options.rpe.delta = args.rpe_delta;
  options.rpe.unit = ParseRpeUnit(args.rpe_unit);
  options.rpe.all_pairs = !args.rpe_consecutive;
  options.allow_frame_offset = args.allow_frame_offset;
  options.Check();
  const TrajectoryFormat gt_format = ParseTrajectoryFormat(args.gt_format);
  const TrajectoryFormat est_format = ParseTrajectoryFormat(args.est_format);

  // Repeated stamps stay (with a warning), as evo keeps them.
  Trajectory gt = ReadTrajectory(args.gt_file, gt_format, DuplicateTimestamps::kKeepAll);
  if (!args.body_from_camera_file.empty()) {
    gt = ChangeSensorFrame(gt, ReadRigidTransform(args.body_from_camera_file));
  }
  const Trajectory est = ReadTrajectory(args.est_file, est_format, DuplicateTimestamps::kKeepAll);
  const EvaluationResult result = EvaluateTrajectories(gt, est, options);

  std::cout << fmt::format("ground truth  {} ({} poses, {:.1f} s, {:.2f} m)\n", args.gt_file,
                           gt.size(), DurationSeconds(gt), PathLengthMeters(gt))
            << fmt::format("estimate      {} ({} poses, {:.1f} s, {:.2f} m)\n", args.est_file,
                           est.size(), DurationSeconds(est), PathLengthMeters(est))
            << FormatEvaluationTable(result);
  if (!args.json_file.empty()) {
    WriteFileAtomically(args.json_file, EvaluationJson(result));
    std::cout << "json          " << args.json_file << '\n';
  }
}

}  // namespace

void RegisterEvalCommand(CLI::App& app) {
  auto args = std::make_shared<EvalArgs>();
  auto* cmd = app.add_subcommand(
      "eval",
      "Compare an estimated trajectory with ground truth: associate by time, align, then "
      "ATE and RPE statistics (evo_ape / evo_rpe compatible)");
  cmd->add_option("--gt", args->gt_file, "Ground-truth trajectory file (tum, euroc, orbslam3)")
      ->required();
  cmd->add_option("--est", args->est_file, "Estimated trajectory file (tum, euroc, orbslam3)")
      ->required();
  cmd->add_option("--align", args->align, "Alignment: se3|sim3|posyaw|none")->capture_default_str();
  cmd->add_option("--max-diff", args->max_diff_s,
                  "Largest time difference of an associated pose pair (s)")
      ->check(CLI::PositiveNumber)
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  cmd->add_option("--t-offset", args->offset_s,
                  "Offset added to the estimate's timestamps before association (s)")
      ->check(CLI::Range(-1e6, 1e6))
      ->capture_default_str();
  cmd->add_flag("--evo-association", args->evo_association,
                "Keep evo's repeated matches instead of strictly one-to-one pairs");
  cmd->add_option("--rpe-delta", args->rpe_delta, "RPE pose-pair distance (frames or metres)")
      ->capture_default_str();
  cmd->add_option("--rpe-unit", args->rpe_unit, "RPE delta unit: frames|m")->capture_default_str();
  cmd->add_flag("--rpe-consecutive", args->rpe_consecutive,
                "RPE on non-overlapping consecutive pairs (evo's default) instead of all pairs");
  cmd->add_option("--json", args->json_file, "Also write the results as JSON to this file");
  cmd->add_flag("--allow-frame-offset", args->allow_frame_offset,
                "Measure although the aligned orientations differ by a near-constant rotation "
                "over 5 deg (by default an error: estimate and truth describe different frames, "
                "e.g. camera against body)");
  cmd->add_option("--body-from-camera", args->body_from_camera_file,
                  "Move the ground truth (body poses) into the camera with this rigid transform "
                  "(a run's body_from_camera.txt) and compare the camera trajectory.txt: needed "
                  "for monocular runs, whose unknown scale makes trajectory_body.txt wrong")
      ->check(CLI::ExistingFile);
  cmd->add_option("--gt-format", args->gt_format, "Ground-truth format: auto|tum|euroc|orbslam3")
      ->capture_default_str();
  cmd->add_option("--est-format", args->est_format, "Estimate format: auto|tum|euroc|orbslam3")
      ->capture_default_str();
  cmd->callback([args] { RunEval(*args); });
}

}  // namespace pkslam::apps
