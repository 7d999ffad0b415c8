// pkslam view: one self-contained HTML page showing a run in 3-D (viewer/), with further runs
// and bare trajectories beside it.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "core/util/error.h"
#include "viewer/view_data.h"
#include "viewer/view_html.h"

namespace pkslam::apps {

namespace {

struct ViewArgs {
  std::vector<std::filesystem::path> runs;
  std::vector<std::filesystem::path> trajectories;
  std::vector<std::string> labels;
  std::string trajectory_frame = "body";
  std::string trajectory_align = "se3";
  std::string out;
};

std::string AteText(double ate_rmse_m, const std::string& alignment) {
  return ate_rmse_m >= 0 ? fmt::format("ATE {:.4f} m ({})", ate_rmse_m, alignment)
                         : std::string("no ground truth");
}

}  // namespace

void RegisterViewCommand(CLI::App& app) {
  auto o = std::make_shared<ViewOptions>();
  auto page = std::make_shared<ViewPageOptions>();
  auto args = std::make_shared<ViewArgs>();
  auto* cmd = app.add_subcommand(
      "view",
      "A run in 3-D in the browser: one self-contained HTML file (trajectory coloured by ATE, "
      "ground truth, keyframes by rule, map points, dense cloud, axes, grid, scale bar, "
      "timeline), with further runs and other systems' trajectories beside it");
  cmd->add_option("--run", args->runs,
                  "Run output folder (pkslam run --out); repeat to add runs: the first is shown "
                  "in full, the others as their trajectory and keyframes")
      ->required();
  cmd->add_option("--trajectory", args->trajectories,
                  "A bare trajectory to add (TUM, EuRoC or ORB-SLAM3 f_*.txt; repeatable); "
                  "needs --gt or --dataset");
  cmd->add_option("--label", args->labels,
                  "Legend name of a --trajectory: the k-th --label names the k-th --trajectory "
                  "(default: its file name)");
  cmd->add_option("--trajectory-frame", args->trajectory_frame,
                  "The sensor the --trajectory files describe: body (IMU; moved into the first "
                  "run's camera with its body_from_camera.txt) or camera")
      ->check(CLI::IsMember({"body", "camera"}))
      ->capture_default_str();
  cmd->add_option("--trajectory-align", args->trajectory_align,
                  "Alignment of the --trajectory files to the ground truth: se3, or sim3 for "
                  "scale-free (monocular) estimates")
      ->check(CLI::IsMember({"se3", "sim3"}))
      ->capture_default_str();
  cmd->add_option("--gt", o->ground_truth, "Ground truth (EuRoC csv or TUM)");
  cmd->add_option("--dataset", o->dataset, "Dataset folder: its ground truth when --gt is absent");
  cmd->add_option("--cloud", o->cloud, "Dense cloud or mesh PLY (default: RUN/dense.ply if any)");
  cmd->add_option("--max-points", o->max_map_points, "Map points shown at most")
      ->capture_default_str();
  cmd->add_option("--max-cloud-points", o->max_cloud_points, "Cloud points shown at most")
      ->capture_default_str();
  cmd->add_option("--three-js", page->three_dir, "Folder of three.min.js (libjs-three)")
      ->capture_default_str();
  cmd->add_option("--out", args->out, "Output HTML file (default: the first run's view.html)");
  cmd->callback([o, page, args] {
    if (args->labels.size() > args->trajectories.size()) {
      throw OptionError(fmt::format("option --label: {} labels for {} --trajectory files",
                                    args->labels.size(), args->trajectories.size()));
    }
    o->run = args->runs.front();
    o->more_runs.assign(args->runs.begin() + 1, args->runs.end());
    for (std::size_t k = 0; k < args->trajectories.size(); ++k) {
      o->trajectories.push_back({args->trajectories[k],
                                 k < args->labels.size() ? args->labels[k] : std::string(),
                                 ParseTrajectorySensorFrame(args->trajectory_frame)});
    }
    o->trajectory_alignment = ParseAlignmentMethod(args->trajectory_align);
    const std::filesystem::path file =
        args->out.empty() ? o->run / "view.html" : std::filesystem::path(args->out);
    const ViewData data = LoadViewData(*o);
    WriteViewPage(data, file, *page);
    std::cout << fmt::format(
        "{}: {} poses, {} keyframes, {} map points, {} cloud points, {}; {:.1f} MB\n",
        file.string(), data.estimate.size(), data.keyframes.size(), data.map_points.size(),
        data.cloud.size(), AteText(data.ate_rmse_m, data.alignment),
        static_cast<double>(std::filesystem::file_size(file)) / 1e6);
    for (const ViewTrack& t : data.tracks) {
      std::cout << fmt::format("  + {} ({}): {} poses, {} keyframes, {}\n", t.label, t.source,
                               t.estimate.size(), t.keyframes.size(),
                               AteText(t.ate_rmse_m, t.alignment));
    }
  });
}

}  // namespace pkslam::apps
