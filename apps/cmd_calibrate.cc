// pkslam calibrate: the rig's calibration from an ordinary flight, no target board
// (docs/calibration.md). A run with online calibration whose final adjustment takes every
// observation of the whole map, the refined files, a report, and (with ground truth) the ATE of
// a run with the file's calibration against one with the refined files fed back.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "apps/calibration_flags.h"
#include "apps/cli_errors.h"
#include "apps/commands.h"
#include "bench/process.h"
#include "core/util/error.h"
#include "core/util/output_file.h"
#include "core/util/output_guard.h"
#include "core/util/project_file.h"
#include "evaluation/evaluate.h"
#include "io/trajectory.h"
#include "system/run_dataset.h"

namespace pkslam::apps {
namespace {

namespace fs = std::filesystem;

struct CalibrateArgs {
  std::string dataset;
  std::string sensor = "stereo-inertial";
  std::string settings;
  std::string vocabulary;
  std::string out = "calibration";
  std::uint64_t seed = 0;
  bool deterministic = false;
  bool no_verify = false;
  // What the calibration run estimates beyond the defaults (AddCalibrationFreedomFlags).
  OnlineCalibrationOptions calibration;
  bool quiet = false;
  std::string python = "/usr/bin/python3";
};

struct Leg {
  std::string label;
  fs::path dir;
  std::optional<double> ate_m;
  std::string note;
};

std::optional<double> BodyAte(const fs::path& gt_file, const fs::path& run, std::string* note) {
  try {
    const Trajectory gt = ReadTrajectory(gt_file, TrajectoryFormat::kAuto);
    const Trajectory est = ReadTrajectory(run / "trajectory_body.txt", TrajectoryFormat::kTum);
    EvaluationOptions options;
    options.compute_rpe = false;
    return EvaluateTrajectories(gt, est, options).ate_translation_m.rmse;
  } catch (const Error& e) {
    *note = e.what();
    return std::nullopt;
  }
}

std::string Table(const CalibrationReport& report) {
  std::string s =
      "| parameter | unit | file | estimate | sigma | (file - estimate) / sigma | freed |\n"
      "|---|---|---|---|---|---|---|\n";
  for (const CalibrationParameter& p : report.parameters) {
    const std::string ratio =
        p.free && p.sigma > 0 ? fmt::format("{:.1f}", (p.file - p.estimate) / p.sigma) : "";
    s += fmt::format("| {} | {} | {:.6g} | {:.6g} | {} | {} | {} |\n", p.name, p.unit, p.file,
                     p.estimate, p.free && p.sigma > 0 ? fmt::format("{:.2g}", p.sigma) : "",
                     ratio, p.free ? "yes" : "no");
  }
  return s;
}

void WriteReport(const CalibrateArgs& args, const RunSummary& run, const std::vector<Leg>& legs,
                 bool plotted, const fs::path& out) {
  const CalibrationReport& r = run.calibration;
  std::string md = fmt::format("# pkslam calibrate: {} ({})\n\n", args.dataset, args.sensor);
  md += fmt::format(
      "A run with online calibration ({} frames, {} tracked, {} adjustments while mapping), then "
      "one adjustment over every keyframe and observation of the final map. The extrinsic rows "
      "are the change from the file (rotation deg, translation mm, left perturbation; imu in "
      "cam0's frame, stereo in cam1's); the time offset t_imu = t_cam + offset.\n\n",
      run.frames, run.tracked, r.history.size());
  md += Table(r);
  if (!r.frozen.empty()) {
    md += "\nFrozen (not observable in this flight):\n\n";
    for (const auto& [group, reason] : r.frozen) md += fmt::format("- {}: {}\n", group, reason);
  }
  md += "\n";
  if (run.calibration_warnings.empty()) {
    md += "No file value is more than 3 sigma from the estimate.\n";
  } else {
    md += "File values more than 3 sigma from the estimate:\n\n";
    for (const std::string& w : run.calibration_warnings) md += "- " + w + "\n";
  }
  md += "\nRefined files: `calibration/cam0/sensor.yaml`, `calibration/cam1/sensor.yaml` "
        "(EuRoC; replace mav0/cam*/sensor.yaml), `calibration/settings.yaml` (ORB-SLAM3 v1.0; "
        "`pkslam run --settings`).\n";
  if (plotted) {
    md += "\n![calibration estimates over the flight](calibration_history.png)\n";
  }
  if (!legs.empty()) {
    md += "\n## ATE against ground truth (body trajectory, SE(3) alignment)\n\n"
          "| run | folder | ATE [m] |\n|---|---|---|\n";
    for (const Leg& l : legs) {
      md += fmt::format("| {} | {} | {} |\n", l.label, l.dir.filename().string(),
                        l.ate_m ? fmt::format("{:.4f}", *l.ate_m) : "failed: " + l.note);
    }
    md += "\nOne run each: thread timing moves a stereo-inertial ATE by about 10-20% from run to "
          "run (docs/calibration.md).\n";
  }
  WriteFileAtomically(out / "report.md", md);
}

void RunCalibrate(const CalibrateArgs& args) {
  const auto sensor = ParseSensor(args.sensor);
  if (!sensor) throw OptionError(fmt::format("unknown --sensor '{}'", args.sensor));
  if (!IsInertial(*sensor) && !IsStereo(*sensor)) {
    throw OptionError(fmt::format(
        "--sensor {}: calibration needs a stereo rig or an IMU (a monocular map has no metric "
        "scale to hold the intrinsics against)",
        args.sensor));
  }
  const fs::path out = args.out;
  CheckOwnedDirectory(out / "calibration", "settings.yaml");  // replaced at the end
  fs::create_directories(out);
  RunOptions base;
  base.dataset = args.dataset;
  if (!args.settings.empty()) base.settings = args.settings;
  if (!args.vocabulary.empty()) base.vocabulary = args.vocabulary;
  base.quiet = args.quiet;
  base.system.sensor = *sensor;
  base.system.seed = args.seed;
  base.system.deterministic = args.deterministic;

  RunOptions calibrate = base;
  calibrate.out = out / "run";
  OnlineCalibrationOptions& c = calibrate.system.mapping.calibration;
  c = args.calibration;
  c.enabled = true;
  c.final_max_observations_per_keyframe = 0;
  c.final_iterations_first = 30;
  c.final_iterations_second = 15;
  fmt::print("calibrate: mapping with online calibration -> {}\n", calibrate.out.string());
  const RunSummary run = RunDataset(calibrate);
  RemoveOwnedDirectory(out / "calibration", "settings.yaml");
  fs::copy(calibrate.out / "calibration", out / "calibration", fs::copy_options::recursive);

  const fs::path script = FindProjectFile("evaluation/calibration_plot.py");
  bool plotted = false;
  if (fs::exists(args.python) && fs::exists(script)) {
    const bench::ProcessResult p = bench::RunProcess({args.python, script.string(),
                                        (calibrate.out / "stats.json").string(),
                                        (out / "calibration_history.png").string(), "--title",
                                        "pkslam calibrate: " + fs::path(args.dataset).filename().string()},
                                       out / "plot.log", 300.0);
    plotted = p.ok();
  }

  std::vector<Leg> legs;
  const std::optional<fs::path> gt = FindDatasetGroundTruth(args.dataset);
  if (gt && !args.no_verify) {
    RunOptions before = base;
    before.out = out / "before";
    RunOptions after = base;
    after.out = out / "after";
    after.settings = out / "calibration" / "settings.yaml";
    for (const auto& [label, options] :
         {std::pair<std::string, RunOptions>{"the file's calibration (--calibrate off)", before},
          std::pair<std::string, RunOptions>{"online calibration (the calibration run)",
                                             calibrate},
          std::pair<std::string, RunOptions>{"the refined files fed back (--calibrate off)",
                                             after}}) {
      if (options.out != calibrate.out) {
        fmt::print("calibrate: verifying with {} -> {}\n", label, options.out.string());
        RunDataset(options);
      }
      Leg leg{label, options.out, std::nullopt, ""};
      leg.ate_m = BodyAte(*gt, options.out, &leg.note);
      legs.push_back(leg);
    }
  }
  WriteReport(args, run, legs, plotted, out);
  fmt::print("calibrate: {} parameters estimated, {} warning(s); report {}\n",
             std::count_if(run.calibration.parameters.begin(), run.calibration.parameters.end(),
                           [](const CalibrationParameter& p) { return p.free; }),
             run.calibration_warnings.size(), (out / "report.md").string());
  for (const Leg& l : legs) {
    fmt::print("  ATE with {}: {}\n", l.label,
               l.ate_m ? fmt::format("{:.4f} m", *l.ate_m) : "failed (" + l.note + ")");
  }
}

}  // namespace

void RegisterCalibrateCommand(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Estimate the rig's calibration from an ordinary flight (no target): refined EuRoC and "
      "ORB-SLAM3 files, a report, and with ground truth the ATE before and after");
  cmd->add_option("--dataset", args->dataset, "EuRoC dataset folder")->required();
  cmd->add_option("--sensor", args->sensor, "Sensor configuration")
      ->check(OneOf({"stereo", "stereo-inertial", "mono-inertial"},
                    "calibration needs a stereo rig or an IMU (a monocular map has no metric "
                    "scale to hold the intrinsics against)"))
      ->capture_default_str();
  cmd->add_option("--settings", args->settings,
                  "ORB-SLAM3 v1.0 settings file (EuRoC: default from the sensor.yaml files)");
  cmd->add_option("--vocabulary", args->vocabulary, "ORB vocabulary (DBoW2 .txt or pkslam .bin)");
  cmd->add_option("--out", args->out, "Output folder")->capture_default_str();
  cmd->add_option("--seed", args->seed, "Run seed")->capture_default_str();
  cmd->add_flag("--deterministic", args->deterministic,
                "Local mapping in lock-step: identical output run to run");
  cmd->add_flag("--no-verify", args->no_verify,
                "Skip the two runs that measure ATE with the file's and the refined calibration");
  AddCalibrationFreedomFlags(cmd, &args->calibration, "");
  cmd->add_flag("--quiet", args->quiet, "No progress lines");
  cmd->add_option("--python", args->python, "Python with matplotlib, for the plot")
      ->capture_default_str();
  cmd->callback([args] { RunCalibrate(*args); });
}

}  // namespace pkslam::apps
