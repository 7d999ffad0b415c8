// pkslam view: one self-contained HTML page showing a run in 3-D (viewer/).
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "apps/commands.h"
#include "viewer/view_data.h"
#include "viewer/view_html.h"

namespace pkslam::apps {

void RegisterViewCommand(CLI::App& app) {
  auto o = std::make_shared<ViewOptions>();
  auto page = std::make_shared<ViewPageOptions>();
  auto out = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand(
      "view",
      "A run in 3-D in the browser: one self-contained HTML file (trajectory coloured by ATE, "
      "ground truth, keyframes by rule, map points, dense cloud, timeline)");
  cmd->add_option("--run", o->run, "Run output folder (pkslam run --out)")->required();
  cmd->add_option("--gt", o->ground_truth, "Ground truth (EuRoC csv or TUM)");
  cmd->add_option("--dataset", o->dataset, "Dataset folder: its ground truth when --gt is absent");
  cmd->add_option("--cloud", o->cloud, "Dense cloud or mesh PLY (default: RUN/dense.ply if any)");
  cmd->add_option("--max-points", o->max_map_points, "Map points shown at most")
      ->capture_default_str();
  cmd->add_option("--max-cloud-points", o->max_cloud_points, "Cloud points shown at most")
      ->capture_default_str();
  cmd->add_option("--three-js", page->three_dir, "Folder of three.min.js (libjs-three)")
      ->capture_default_str();
  cmd->add_option("--out", *out, "Output HTML file (default RUN/view.html)");
  cmd->callback([o, page, out] {
    const std::filesystem::path file =
        out->empty() ? o->run / "view.html" : std::filesystem::path(*out);
    const ViewData data = LoadViewData(*o);
    WriteViewPage(data, file, *page);
    std::cout << fmt::format(
        "{}: {} poses, {} keyframes, {} map points, {} cloud points{}; {:.1f} MB\n", file.string(),
        data.estimate.size(), data.keyframes.size(), data.map_points.size(), data.cloud.size(),
        data.ate_rmse_m >= 0 ? fmt::format(", ATE {:.4f} m ({})", data.ate_rmse_m, data.alignment)
                             : std::string(", no ground truth"),
        static_cast<double>(std::filesystem::file_size(file)) / 1e6);
  });
}

}  // namespace pkslam::apps
