// pkslam eval: ATE/RPE of estimated trajectories against ground truth (evo-compatible), the
// segment errors of rpg_trajectory_evaluation, saved errors and figures.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "bench/process.h"
#include "core/util/error.h"
#include "core/util/json_writer.h"
#include "core/util/output_file.h"
#include "core/util/project_file.h"
#include "evaluation/evaluate.h"
#include "evaluation/evaluation_output.h"
#include "io/kitti_dataset.h"
#include "io/rigid_transform_file.h"
#include "io/trajectory.h"

namespace pkslam::apps {
namespace {

struct EvalArgs {
  std::string gt_file;
  std::vector<std::string> est_files;
  std::vector<std::string> labels;
  std::string gt_format = "auto";
  std::string est_format = "auto";
  std::string align = "se3";
  double max_diff_s = 0.01;
  double offset_s = 0.0;
  bool evo_association = false;
  double rpe_delta = 1.0;
  std::string rpe_unit = "frames";
  bool rpe_consecutive = false;
  bool rpe_all_pairs = false;
  std::string segments = "auto";
  std::string json_file;
  std::string body_from_camera_file;
  bool allow_frame_offset = false;
  std::string plot_dir;
  std::string save_aligned_dir;
  std::string save_errors_dir;
  bool kitti = false;
  std::vector<double> kitti_lengths;
  std::string times_file;
};

// KITTI poses files (12 numbers per line, no time): their first data line has 12 fields.
bool IsKittiPoses(const std::filesystem::path& file) {
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    std::stringstream fields(line);
    std::string first;
    if (!(fields >> first) || first[0] == '#') continue;
    int n = 1;
    for (std::string f; fields >> f;) ++n;
    return n == 12;
  }
  return false;
}

// A trajectory file of any format pkslam reads; KITTI poses get their stamps from --times, or
// from ../sequences/NN/times.txt beside poses/NN.txt.
Trajectory ReadForEval(const std::string& file, TrajectoryFormat format,
                       const std::string& times_file) {
  if (format == TrajectoryFormat::kAuto && std::filesystem::exists(file) && IsKittiPoses(file)) {
    std::filesystem::path times = times_file;
    if (times.empty()) times = KittiTimesFor(file);
    if (times.empty()) {
      throw InputError(file,
                       "KITTI poses (12 numbers per line) carry no times: give --times "
                       "sequences/NN/times.txt");
    }
    return ReadKittiPoses(file, ReadKittiTimes(times));
  }
  return ReadTrajectory(file, format, DuplicateTimestamps::kKeepAll);
}

// "auto" (rpg's 10-50% of the path), "none", or a comma-separated list of lengths in metres.
void ParseSegments(const std::string& text, EvaluationOptions& options) {
  if (text == "none") {
    options.compute_segments = false;
    return;
  }
  options.compute_segments = true;
  if (text == "auto") return;
  std::stringstream list(text);
  std::string item;
  while (std::getline(list, item, ',')) {
    std::size_t used = 0;
    double length = 0.0;
    try {
      length = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size()) {
      throw OptionError(
          fmt::format("--segments {}: '{}' is not a length in metres (give auto, "
                      "none, or lengths like 10,20,40)",
                      text, item));
    }
    options.segments.lengths_m.push_back(length);
  }
}

EvaluationOptions OptionsFrom(const EvalArgs& args) {
  EvaluationOptions options;
  options.alignment = ParseAlignmentMethod(args.align);
  options.association.max_diff_s = args.max_diff_s;
  options.association.offset_s = args.offset_s;
  options.association.one_to_one = !args.evo_association;
  options.rpe.delta = args.rpe_delta;
  options.rpe.unit = ParseRpeUnit(args.rpe_unit);
  if (args.rpe_all_pairs && args.rpe_consecutive) {
    throw OptionError("--rpe-all-pairs and --rpe-consecutive exclude each other");
  }
  options.rpe.all_pairs = args.rpe_all_pairs;
  ParseSegments(args.segments, options);
  options.compute_kitti = args.kitti || !args.kitti_lengths.empty();
  if (!args.kitti_lengths.empty()) options.kitti.lengths_m = args.kitti_lengths;
  options.allow_frame_offset = args.allow_frame_offset;
  options.Check();
  return options;
}

// Runs evaluation/eval_plots.py over the files written into DIR/data; returns the figures.
std::vector<std::string> DrawPlots(const std::filesystem::path& dir) {
  const std::filesystem::path script = FindProjectFile("evaluation/eval_plots.py");
  if (!std::filesystem::exists(script)) throw Error("plot script not found: " + script.string());
  const std::filesystem::path log = dir / "plots.log";
  const bench::ProcessResult p = bench::RunProcess({"/usr/bin/python3", script.string(), "--data",
                                                    (dir / "data").string(), "--out", dir.string()},
                                                   log, 600.0);
  if (!p.ok()) {
    throw Error(
        fmt::format("evaluation/eval_plots.py failed ({}); see {}", p.Describe(), log.string()));
  }
  std::filesystem::remove(log);
  std::vector<std::string> figures;
  std::ifstream index(dir / "figures.tsv");
  for (std::string line; std::getline(index, line);) {
    if (!line.empty()) figures.push_back(line.substr(0, line.find('\t')));
  }
  return figures;
}

void WriteJson(const std::string& file, const std::vector<std::string>& labels,
               const std::vector<std::string>& est_files,
               const std::vector<EvaluationResult>& results) {
  if (results.size() == 1) {
    WriteFileAtomically(file, EvaluationJson(results.front()));
    return;
  }
  JsonWriter json(2);
  json.BeginObject().Key("estimates").BeginArray();
  for (std::size_t k = 0; k < results.size(); ++k) {
    json.BeginObject().Member("label", labels[k]).Member("file", est_files[k]).Key("result");
    WriteEvaluationJson(results[k], json);
    json.EndObject();
  }
  json.EndArray().EndObject();
  WriteFileAtomically(file, json.str());
}

void RunEval(const EvalArgs& args) {
  const EvaluationOptions options = OptionsFrom(args);
  const TrajectoryFormat gt_format = ParseTrajectoryFormat(args.gt_format);
  const TrajectoryFormat est_format = ParseTrajectoryFormat(args.est_format);
  if (!args.labels.empty() && args.labels.size() != args.est_files.size()) {
    throw OptionError(
        fmt::format("--label given {} times for {} --est files: give one per "
                    "estimate, or none",
                    args.labels.size(), args.est_files.size()));
  }

  // Repeated stamps stay (with a warning), as evo keeps them.
  Trajectory gt = ReadForEval(args.gt_file, gt_format, args.times_file);
  if (!args.body_from_camera_file.empty()) {
    gt = ChangeSensorFrame(gt, ReadRigidTransform(args.body_from_camera_file));
  }
  std::vector<std::filesystem::path> est_paths(args.est_files.begin(), args.est_files.end());
  const std::vector<std::string> labels =
      args.labels.empty() ? UniqueLabels(est_paths) : args.labels;
  std::vector<Trajectory> estimates;
  std::vector<EvaluationResult> results;
  for (const std::string& file : args.est_files) {
    estimates.push_back(ReadForEval(file, est_format, args.times_file));
    results.push_back(EvaluateTrajectories(gt, estimates.back(), options));
  }

  std::cout << fmt::format("ground truth  {} ({} poses, {:.1f} s, {:.2f} m)\n", args.gt_file,
                           gt.size(), DurationSeconds(gt), PathLengthMeters(gt));
  for (std::size_t k = 0; k < estimates.size(); ++k) {
    std::cout << fmt::format(
        "estimate      {}{} ({} poses, {:.1f} s, {:.2f} m)\n", args.est_files[k],
        estimates.size() > 1 ? fmt::format(" [{}]", labels[k]) : "", estimates[k].size(),
        DurationSeconds(estimates[k]), PathLengthMeters(estimates[k]));
  }
  if (results.size() == 1) {
    std::cout << FormatEvaluationTable(results.front());
  } else {
    std::cout << fmt::format("alignment     {}; RPE delta {} {}, {} pairs\n\n",
                             AlignmentMethodName(options.alignment), options.rpe.delta,
                             RpeUnitName(options.rpe.unit),
                             options.rpe.all_pairs ? "all" : "consecutive")
              << FormatComparisonTable(labels, results);
    for (std::size_t k = 0; k < results.size(); ++k) {
      if (!results[k].segments) continue;
      std::cout << "\n[" << labels[k] << "]" << FormatSegmentTable(*results[k].segments);
    }
  }
  if (!args.json_file.empty()) {
    WriteJson(args.json_file, labels, args.est_files, results);
    std::cout << "json          " << args.json_file << '\n';
  }
  auto save_all = [&](const std::filesystem::path& dir, bool aligned, bool errors) {
    for (std::size_t k = 0; k < results.size(); ++k) {
      if (aligned) WriteAlignedEstimate(dir, labels[k], estimates[k], results[k]);
      if (errors) WriteErrorFiles(dir, labels[k], estimates[k], results[k]);
    }
  };
  if (!args.save_aligned_dir.empty()) {
    save_all(args.save_aligned_dir, true, false);
    std::cout << "aligned       " << args.save_aligned_dir << " (LABEL_aligned.tum)\n";
  }
  if (!args.save_errors_dir.empty()) {
    save_all(args.save_errors_dir, false, true);
    std::cout << "errors        " << args.save_errors_dir
              << " (LABEL_poses.csv, LABEL_rpe.csv, LABEL_segments.csv)\n";
  }
  if (!args.plot_dir.empty()) {
    const std::filesystem::path dir = args.plot_dir;
    save_all(dir / "data", true, true);
    OutputFile index(dir / "data" / "estimates.tsv");
    index.stream() << "label\tfile\talignment\tgt\n";
    for (std::size_t k = 0; k < results.size(); ++k) {
      index.stream() << labels[k] << '\t' << args.est_files[k] << '\t'
                     << AlignmentMethodName(options.alignment) << '\t' << args.gt_file << '\n';
    }
    index.Commit();
    const std::vector<std::string> figures = DrawPlots(dir);
    std::cout << fmt::format("plots         {} ({} figures: {})\n", args.plot_dir, figures.size(),
                             fmt::join(figures, ", "));
  }
}

}  // namespace

void RegisterEvalCommand(CLI::App& app) {
  auto args = std::make_shared<EvalArgs>();
  auto* cmd = app.add_subcommand(
      "eval",
      "Compare estimated trajectories with ground truth: associate by time, align, then ATE, "
      "RPE (evo_ape / evo_rpe definitions and defaults), the relative error over segment "
      "lengths (rpg_trajectory_evaluation) and with --kitti KITTI's odometry metric; several "
      "--est are compared in one table, --plot draws the figures");
  cmd->add_option("--gt", args->gt_file,
                  "Ground-truth trajectory file (tum, euroc, orbslam3, KITTI poses/NN.txt)")
      ->required();
  cmd->add_option("--est", args->est_files,
                  "Estimated trajectory file(s) (tum, euroc, orbslam3); repeat or list several "
                  "to compare them")
      ->required();
  cmd->add_option("--label", args->labels,
                  "A name per --est for tables, files and legends (default: the file's stem, or "
                  "its folder's name for trajectory.txt and the like)");
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
  cmd->add_option("--rpe-delta", args->rpe_delta,
                  "RPE pose-pair distance (frames or metres; evo's --delta)")
      ->capture_default_str();
  cmd->add_option("--rpe-unit", args->rpe_unit, "RPE delta unit: frames|m (evo's --delta_unit f|m)")
      ->capture_default_str();
  cmd->add_flag("--rpe-all-pairs", args->rpe_all_pairs,
                "RPE from every pose (evo --all_pairs) instead of non-overlapping consecutive "
                "pairs (evo's default)");
  cmd->add_flag("--rpe-consecutive", args->rpe_consecutive,
                "Non-overlapping consecutive RPE pairs: the default (kept for old scripts)");
  cmd->add_option("--segments", args->segments,
                  "Relative error over segment lengths: auto (rpg's 10,20,30,40,50% of the "
                  "path), none, or lengths in metres like 10,20,40")
      ->capture_default_str();
  cmd->add_flag("--kitti", args->kitti,
                "Also KITTI odometry's metric (the devkit's): translation error in % and rotation "
                "error in deg/100 m over segments of 100-800 m starting every 10 frames");
  cmd->add_option("--kitti-lengths", args->kitti_lengths,
                  "Segment lengths of the KITTI metric in metres instead of the devkit's 100..800 "
                  "(e.g. 5,10,20 for a short simulated flight; implies --kitti)")
      ->delimiter(',');
  cmd->add_option("--times", args->times_file,
                  "times.txt of a KITTI sequence: the stamps of files in KITTI's pose format (12 "
                  "numbers per line; default: sequences/NN/times.txt beside poses/NN.txt)");
  cmd->add_option("--json", args->json_file, "Also write the results as JSON to this file");
  cmd->add_option("--plot", args->plot_dir,
                  "Draw figures into this folder (matplotlib): trajectories (top view, xyz, "
                  "roll/pitch/yaw) against truth, ATE over time and along the path, RPE over "
                  "time, segment errors and ATE as box plots; the data beside them in DIR/data");
  cmd->add_option("--save-aligned", args->save_aligned_dir,
                  "Write each aligned estimate to DIR/LABEL_aligned.tum");
  cmd->add_option("--save-errors", args->save_errors_dir,
                  "Write per-pose ATE, per-pair RPE and per-segment errors to DIR/LABEL_*.csv");
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
