// pkslam dense: a dense point cloud from a run's keyframes (see dense/dense_cloud.h).
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "apps/commands.h"
#include "core/util/error.h"
#include "core/util/json_writer.h"
#include "dense/dense_cloud.h"

namespace pkslam::apps {
namespace {

namespace fs = std::filesystem;

struct DenseArgs {
  std::string run;
  std::string dataset;
  std::string settings;
  std::string out;
  std::string json;
  bool colour = false;
  dense::DenseOptions options;
};

void RunDense(const DenseArgs& args) {
  args.options.Check();
  const fs::path keyframes_file = fs::path(args.run) / "keyframes.txt";
  if (!fs::is_directory(args.run)) throw InputError(args.run, "run directory does not exist");
  if (!fs::exists(keyframes_file)) {
    throw InputError(keyframes_file, "no keyframes.txt (is this a `pkslam run` output?)");
  }
  const Trajectory keyframes = ReadTrajectory(keyframes_file, TrajectoryFormat::kTum);
  const auto source = dense::KeyframeImageSource::Open(
      args.dataset, args.settings.empty() ? std::nullopt : std::optional<fs::path>(args.settings));
  dense::DenseStats stats;
  const dense::PointCloud cloud = BuildDenseCloud(keyframes, source, args.options, &stats);
  if (cloud.empty()) {
    throw Error("the dense cloud is empty (no depth passed the multi-view filter)");
  }
  const auto colour = args.colour ? dense::PlyColour::kRgb : dense::PlyColour::kGrey;
  dense::WritePly(cloud, args.out, colour,
                  fmt::format("pkslam dense: {} keyframes, voxel {} m, min views {}",
                              stats.keyframes_used, args.options.voxel_m, args.options.min_views));
  fmt::print("keyframes {} used {} (missing {}), depth source {}, max depth {:.2f} m\n",
             stats.keyframes, stats.keyframes_used, stats.missing_t_ns.size(),
             source.source() == dense::DepthSource::kStereo ? "stereo SGBM" : "RGB-D",
             args.options.MaxDepth());
  fmt::print(
      "depth points {} (valid depth {:.1f}% of pixels), {} ({:.1f}%) confirmed by >= {} "
      "keyframes, {} voxels of {} m\n",
      stats.depth_points, 100.0 * stats.mean_valid_depth_share, stats.consistent_points,
      stats.depth_points > 0 ? 100.0 * static_cast<double>(stats.consistent_points) /
                                   static_cast<double>(stats.depth_points)
                             : 0.0,
      args.options.min_views, stats.points, args.options.voxel_m);
  fmt::print("{:.1f} s; cloud: {}\n", stats.seconds, args.out);
  if (!args.json.empty()) {
    JsonWriter json;
    json.BeginObject();
    json.Member("run", args.run);
    json.Member("dataset", args.dataset);
    json.Member("cloud", args.out);
    json.Member("keyframes", stats.keyframes);
    json.Member("keyframes_used", stats.keyframes_used);
    json.Member("keyframes_missing", static_cast<int>(stats.missing_t_ns.size()));
    json.Member("voxel_m", args.options.voxel_m);
    json.Member("max_depth_m", args.options.MaxDepth());
    json.Member("min_views", args.options.min_views);
    json.Member("consistency_rel", args.options.consistency_rel);
    json.Member("window", args.options.window);
    json.Member("depth_points", static_cast<std::uint64_t>(stats.depth_points));
    json.Member("consistent_points", static_cast<std::uint64_t>(stats.consistent_points));
    json.Member("valid_depth_share", stats.mean_valid_depth_share);
    json.Member("voxels", static_cast<std::uint64_t>(stats.voxels));
    json.Member("points", static_cast<std::uint64_t>(stats.points));
    json.Member("seconds", stats.seconds);
    json.EndObject();
    std::ofstream out(args.json);
    out << json.str();
    if (!out) throw Error(fmt::format("cannot write {}", args.json));
  }
}

}  // namespace

void RegisterDenseCommand(CLI::App& app) {
  auto args = std::make_shared<DenseArgs>();
  auto* cmd = app.add_subcommand(
      "dense",
      "Dense point cloud from a run's keyframes: stereo SGBM (rectified, left-right checked) or "
      "RGB-D depth, kept where >= --min-views keyframes agree, fused in a voxel grid");
  cmd->add_option("--run", args->run, "Run directory of `pkslam run` (keyframes.txt)")->required();
  cmd->add_option("--dataset", args->dataset, "The dataset the run used (EuRoC or TUM RGB-D)")
      ->required();
  cmd->add_option("--out", args->out, "Output cloud (binary PLY)")->required();
  cmd->add_option("--settings", args->settings, "The settings file the run used (if any)");
  dense::DenseOptions& o = args->options;
  cmd->add_option("--voxel", o.voxel_m, "Voxel side (m)")->capture_default_str();
  cmd->add_option("--max-depth", o.max_depth_m, "Largest depth used (m; 0: 4 m)")
      ->capture_default_str();
  cmd->add_option("--min-depth", o.min_depth_m, "Smallest depth used (m)")->capture_default_str();
  cmd->add_option("--min-views", o.min_views,
                  "Keep depths at least N keyframes agree on (itself included; 1: no filter)")
      ->capture_default_str();
  cmd->add_option("--consistency", o.consistency_rel,
                  "Relative depth agreement of a confirming keyframe")
      ->capture_default_str();
  cmd->add_option("--window", o.window,
                  "Keyframes on each side (in keyframe order) that may confirm a depth")
      ->capture_default_str();
  cmd->add_flag("--colour,--color", args->colour,
                "Write red/green/blue (colour images; grey replicated) instead of intensity");
  cmd->add_option("--pixel-step", o.pixel_step, "Use every N-th pixel")->capture_default_str();
  cmd->add_option("--num-disparities", o.stereo.num_disparities,
                  "SGBM disparity range (multiple of 16)")
      ->capture_default_str();
  cmd->add_option("--block-size", o.stereo.block_size, "SGBM block size (odd)")
      ->capture_default_str();
  cmd->add_option("--uniqueness", o.stereo.uniqueness_ratio, "SGBM uniqueness ratio (%)")
      ->capture_default_str();
  cmd->add_option("--lr-max-diff", o.stereo.lr_max_difference,
                  "Left-right check tolerance (px; < 0: off)")
      ->capture_default_str();
  cmd->add_option("--edge-px", o.edge_disparity_px,
                  "Drop stereo pixels at disparity jumps larger than this (px; 0: off)")
      ->capture_default_str();
  cmd->add_option("--json", args->json, "Write the statistics as JSON");
  cmd->add_flag("--quiet", o.quiet, "No progress bar");
  cmd->callback([args] { RunDense(*args); });
}

}  // namespace pkslam::apps
