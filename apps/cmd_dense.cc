// pkslam dense: a dense point cloud from a run's keyframes (see dense/dense_cloud.h).
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "apps/commands.h"
#include "core/util/error.h"
#include "core/util/json_writer.h"
#include "core/util/output_file.h"
#include "dense/dense_cloud.h"
#include "dense/mesh.h"
#include "io/dataset_fingerprint.h"

namespace pkslam::apps {
namespace {

namespace fs = std::filesystem;

struct DenseArgs {
  std::string run;
  std::string dataset;
  std::string settings;
  bool file_calibration = false;
  std::string out;
  std::string json;
  std::string mesh;
  bool colour = false;
  dense::DenseOptions options;
  dense::MeshOptions mesh_options;
};

void RunDense(const DenseArgs& args) {
  args.options.Check();
  if (args.out.empty() && args.mesh.empty()) throw OptionError("dense: give --out and/or --mesh");
  const fs::path keyframes_file = fs::path(args.run) / "keyframes.txt";
  if (!fs::is_directory(args.run)) throw InputError(args.run, "run directory does not exist");
  if (!fs::exists(keyframes_file)) {
    throw InputError(keyframes_file, "no keyframes.txt (is this a `pkslam run` output?)");
  }
  const Trajectory keyframes = ReadTrajectory(keyframes_file, TrajectoryFormat::kTum);
  // The keyframe poses are poses of the run's rectified camera, built from the calibration the
  // run ended with (RUN/calibration/settings.yaml: the file's, or its online estimate).
  std::optional<fs::path> settings;
  if (!args.settings.empty()) {
    settings = args.settings;
  } else if (!args.file_calibration && fs::exists(fs::path(args.run) / "calibration" / "settings.yaml")) {
    settings = fs::path(args.run) / "calibration" / "settings.yaml";
  }
  const auto source =
      dense::KeyframeImageSource::Open(args.dataset, settings, args.options.full_view);
  RequireRunOfDataset(args.run, args.dataset);
  std::optional<dense::MeshStats> mesh;
  dense::DenseStats stats;
  std::optional<PointCloud> filtered_cloud;  // the cloud the filtered-depth mesh pass made
  if (!args.mesh.empty()) {
    dense::MeshOptions mo = args.mesh_options;
    mo.depth = args.options;
    if (mo.filtered_depth) {
      filtered_cloud.emplace();
      mesh =
          dense::BuildFilteredTsdfMesh(keyframes, source, mo, args.mesh, &*filtered_cloud, &stats);
    } else {
      mesh = dense::BuildTsdfMesh(keyframes, source, mo, args.mesh);
    }
    fmt::print(
        "mesh: {} keyframes fused ({} depth; TSDF voxel {} m, truncation {} m), {} vertices, {} "
        "triangles, {:.1f} s, peak memory {:.0f} MiB; {}\n",
        mesh->keyframes_used, mo.filtered_depth ? "multi-view filtered" : "raw", mo.voxel_m,
        mo.truncation_m, mesh->vertices, mesh->triangles, mesh->seconds, mesh->peak_memory_mib,
        args.mesh);
    if (args.out.empty()) {
      if (!args.json.empty()) {
        JsonWriter json;
        json.BeginObject();
        json.Member("run", args.run).Member("dataset", args.dataset).Member("mesh", args.mesh);
        json.Member("mesh_voxel_m", mo.voxel_m).Member("mesh_truncation_m", mo.truncation_m);
        json.Member("mesh_keyframes", mesh->keyframes_used);
        json.Member("mesh_vertices", static_cast<std::uint64_t>(mesh->vertices));
        json.Member("mesh_triangles", static_cast<std::uint64_t>(mesh->triangles));
        json.Member("mesh_seconds", mesh->seconds)
            .Member("mesh_peak_memory_mib", mesh->peak_memory_mib);
        json.EndObject();
        WriteFileAtomically(args.json, json.str());
      }
      return;
    }
  }
  const PointCloud cloud = filtered_cloud
                               ? std::move(*filtered_cloud)
                               : BuildDenseCloud(keyframes, source, args.options, &stats);
  if (cloud.empty()) {
    throw Error("the dense cloud is empty (no depth passed the multi-view filter)");
  }
  const auto colour = args.colour ? PlyColour::kRgb : PlyColour::kGrey;
  WritePly(cloud, args.out, colour,
           fmt::format("pkslam dense: {} keyframes, voxel {} m, min views {}", stats.keyframes_used,
                       args.options.voxel_m, args.options.min_views));
  fmt::print("keyframes {} used {} (missing {}), depth source {}, max depth {:.2f} m\n",
             stats.keyframes, stats.keyframes_used, stats.missing_t_ns.size(),
             source.source() == dense::DepthSource::kStereo ? "stereo SGBM" : "RGB-D",
             args.options.MaxDepth());
  auto share = [&](std::size_t n) {
    return stats.depth_points > 0
               ? 100.0 * static_cast<double>(n) / static_cast<double>(stats.depth_points)
               : 0.0;
  };
  fmt::print(
      "depth points {} (valid depth {:.1f}% of pixels), {} ({:.1f}%) kept: {} confirmed by >= "
      "{} keyframes, {} ({:.1f}%) uncontradicted single-view; {} ({:.1f}%) contradicted; {} "
      "({:.1f}%) deferred to a closer keyframe; {} voxels of {} m\n",
      stats.depth_points, 100.0 * stats.mean_valid_depth_share, stats.consistent_points,
      share(stats.consistent_points), stats.consistent_points - stats.unconfirmed_points,
      args.options.min_views, stats.unconfirmed_points, share(stats.unconfirmed_points),
      stats.contradicted_points, share(stats.contradicted_points), stats.deferred_points,
      share(stats.deferred_points), stats.points, args.options.voxel_m);
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
    json.Member("neighbour_max_depth_m", args.options.NeighbourMaxDepth());
    json.Member("min_views", args.options.min_views);
    json.Member("consistency_rel", args.options.consistency_rel);
    json.Member("window", args.options.window);
    json.Member("depth_points", static_cast<std::uint64_t>(stats.depth_points));
    json.Member("keep_unconfirmed", args.options.keep_unconfirmed);
    json.Member("majority_veto", args.options.majority_veto);
    json.Member("consistent_points", static_cast<std::uint64_t>(stats.consistent_points));
    json.Member("unconfirmed_points", static_cast<std::uint64_t>(stats.unconfirmed_points));
    json.Member("contradicted_points", static_cast<std::uint64_t>(stats.contradicted_points));
    json.Member("deferred_points", static_cast<std::uint64_t>(stats.deferred_points));
    json.Member("defer_ratio", args.options.defer_ratio);
    json.Member("occluder_radius_px", args.options.occluder_radius_px);
    json.Member("unconfirmed_max_depth_m", args.options.unconfirmed_max_depth_m);
    json.Member("p1", args.options.stereo.p1);
    json.Member("p2", args.options.stereo.p2);
    json.Member("block_size", args.options.stereo.block_size);
    json.Member("uniqueness", args.options.stereo.uniqueness_ratio);
    json.Member("pad_borders", args.options.stereo.pad_borders);
    json.Member("full_view", args.options.full_view);
    json.Member("image_width", source.camera().width());
    json.Member("image_height", source.camera().height());
    json.Member("valid_depth_share", stats.mean_valid_depth_share);
    json.Member("voxels", static_cast<std::uint64_t>(stats.voxels));
    json.Member("points", static_cast<std::uint64_t>(stats.points));
    json.Member("seconds", stats.seconds);
    if (mesh) {
      json.Member("mesh", args.mesh);
      json.Member("mesh_voxel_m", args.mesh_options.voxel_m);
      json.Member("mesh_truncation_m", args.mesh_options.truncation_m);
      json.Member("mesh_vertices", static_cast<std::uint64_t>(mesh->vertices));
      json.Member("mesh_triangles", static_cast<std::uint64_t>(mesh->triangles));
      json.Member("mesh_seconds", mesh->seconds);
      json.Member("mesh_peak_memory_mib", mesh->peak_memory_mib);
    }
    json.EndObject();
    WriteFileAtomically(args.json, json.str());
  }
}

}  // namespace

void RegisterDenseCommand(CLI::App& app) {
  auto args = std::make_shared<DenseArgs>();
  auto* cmd = app.add_subcommand(
      "dense",
      "Dense point cloud from a run's keyframes: stereo SGBM (full-view rectified, left-right "
      "checked) or RGB-D depth; depths >= --min-views keyframes agree on are averaged, "
      "single-view depths no keyframe contradicts are kept (views 1); fused in a voxel grid. "
      "--mesh: a triangle mesh by TSDF fusion (Open3D)");
  cmd->add_option("--run", args->run, "Run directory of `pkslam run` (keyframes.txt)")->required();
  cmd->add_option("--dataset", args->dataset, "The dataset the run used (EuRoC or TUM RGB-D)")
      ->required();
  cmd->add_option("--out", args->out, "Output cloud (binary PLY)");
  cmd->add_option("--mesh", args->mesh,
                  "Also (or only) fuse the keyframes' depth maps in a TSDF volume (Open3D) and "
                  "write its triangle mesh here (PLY)");
  cmd->add_option("--mesh-voxel", args->mesh_options.voxel_m, "TSDF voxel side (m)")
      ->capture_default_str();
  cmd->add_flag("!--mesh-raw-depth", args->mesh_options.filtered_depth,
                "Fuse each keyframe's raw depth map into the mesh (default: the depth after the "
                "point cloud's multi-view filter)");
  cmd->add_option("--mesh-truncation", args->mesh_options.truncation_m,
                  "TSDF truncation distance (m)")
      ->capture_default_str();
  cmd->add_option("--settings", args->settings,
                  "Settings for the images (default: RUN/calibration/settings.yaml, the "
                  "calibration the run ended with; else as `pkslam run`)");
  cmd->add_flag("--file-calibration", args->file_calibration,
                "Rectify with the dataset's calibration files even if the run estimated its own");
  dense::DenseOptions& o = args->options;
  cmd->add_option("--voxel", o.voxel_m, "Voxel side (m)")->capture_default_str();
  cmd->add_option("--max-depth", o.max_depth_m, "Largest depth used (m; 0: 4 m)")
      ->capture_default_str();
  cmd->add_option("--min-depth", o.min_depth_m, "Smallest depth used (m)")->capture_default_str();
  cmd->add_option("--neighbour-max-depth", o.neighbour_max_depth_m,
                  "Depths up to this (m) still confirm or contradict other keyframes' depths")
      ->capture_default_str();
  cmd->add_option("--min-views", o.min_views,
                  "Keep depths at least N keyframes agree on (itself included; 1: no filter)")
      ->capture_default_str();
  cmd->add_option("--consistency", o.consistency_rel,
                  "Relative depth agreement of a confirming keyframe")
      ->capture_default_str();
  cmd->add_flag("!--strict-views", o.keep_unconfirmed,
                "Drop every depth fewer than --min-views keyframes agree on (default: keep "
                "those no keyframe that should see them contradicts)");
  cmd->add_flag("!--no-majority-veto", o.majority_veto,
                "Keep confirmed depths even when more keyframes contradict than confirm them");
  cmd->add_option("--unconfirmed-max-depth", o.unconfirmed_max_depth_m,
                  "Keep depths no other keyframe confirms only up to this depth (m; 0: any)")
      ->capture_default_str();
  cmd->add_option("--occluder-radius", o.occluder_radius_px,
                  "A keyframe's surface this close (px) to a depth's line of sight, in front of "
                  "it, contradicts it")
      ->capture_default_str();
  cmd->add_option(
         "--defer-ratio", o.defer_ratio,
         "Drop a depth a confirming keyframe sees from closer than depth / R (its estimate "
         "is better; 0: off)")
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
  cmd->add_option("--p1", o.stereo.p1, "SGBM penalty for 1-px disparity changes (0: 8 x block^2)")
      ->capture_default_str();
  cmd->add_option("--p2", o.stereo.p2, "SGBM penalty for larger changes (0: 32 x block^2)")
      ->capture_default_str();
  cmd->add_flag("!--no-full-view", o.full_view,
                "Stereo: use the run's cropped rectified images (default: rectify onto the full "
                "view of the raw cameras)");
  cmd->add_flag("!--no-pad", o.stereo.pad_borders,
                "Do not pad the stereo pair (SGBM then leaves the image sides without depth)");
  cmd->add_option("--speckle-window", o.stereo.speckle_window_size,
                  "SGBM speckle filter region size (px; 0: off)")
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
