// pkslam planar: planar RGB-D modelling with plane-sampled ICP (rgbd/planar_run.h).
#include <fmt/format.h>

#include "apps/commands.h"
#include "core/util/error.h"
#include "rgbd/planar_run.h"

namespace pkslam::apps {

void RegisterPlanarCommand(CLI::App& app) {
  auto options = std::make_shared<rgbd::PlanarRunOptions>();
  auto settings = std::make_shared<std::string>();
  auto segmentation = std::make_shared<std::string>("region");
  auto fit = std::make_shared<std::string>("ls");
  auto reference = std::make_shared<std::string>("none");
  auto gap = std::make_shared<int>(1);
  auto gaps = std::make_shared<std::vector<int>>();
  auto* cmd = app.add_subcommand(
      "planar",
      "Planar RGB-D modelling: Lab segmentation, plane fits, plane-sampled ICP (TUM folder)");
  auto& o = *options;
  cmd->add_option("--dataset", o.input.dataset, "TUM RGB-D folder (rgb.txt, depth.txt)")
      ->required();
  cmd->add_option("--settings", *settings,
                  "ORB-SLAM3 settings file for the camera (default: DIR/settings.yaml, or TUM's "
                  "calibration for freiburg1/2/3 folders)");
  cmd->add_option("--out", o.out, "Output directory")->capture_default_str();
  cmd->add_option("--lab-threshold", o.frame.lab_threshold,
                  "Region growing: Lab distance threshold")
      ->capture_default_str();
  cmd->add_option("--merge-angle", o.frame.merge_angle_deg, "Merging: largest normal angle [deg]")
      ->capture_default_str();
  cmd->add_option("--merge-rms", o.frame.merge_max_fit_rms_m,
                  "Merging: largest plane-fit RMS of a segment and of a merged segment [m]")
      ->capture_default_str();
  cmd->add_option("--merge-max-points", o.frame.merge_max_points,
                  "Merging: largest merged segment [points] (0: no limit)")
      ->capture_default_str();
  cmd->add_option("--samples", o.frame.samples_per_plane, "Points sampled per plane (N)")
      ->capture_default_str();
  cmd->add_option("--min-plane-points", o.frame.min_sampled_plane_points,
                  "Sample only planes with at least this many points (0: all, as the paper)")
      ->capture_default_str();
  cmd->add_option("--gap", *gap, "Frame gap k: register frames i and i+k")->capture_default_str();
  cmd->add_option("--gaps", *gaps, "Several gaps, e.g. --gaps 1 2 3 4 5 (overrides --gap)");
  cmd->add_option("--segmentation", *segmentation, "region | kmeans")->capture_default_str();
  cmd->add_option("--kmeans-clusters", o.frame.kmeans_clusters, "K-Means: clusters")
      ->capture_default_str();
  cmd->add_option("--kmeans-stride", o.frame.kmeans_stride, "K-Means: pixel stride of the samples")
      ->capture_default_str();
  cmd->add_option("--plane-fit", *fit, "ls (Eq. 6) | pca")->capture_default_str();
  cmd->add_option("--reference", *reference, "none | full-icp (full-point ICP baseline)")
      ->capture_default_str();
  cmd->add_option("--full-stride", o.full_stride, "Full-ICP reference: pixel stride (1: all)")
      ->capture_default_str();
  cmd->add_option("--icp-iterations", o.icp.max_iterations, "ICP iteration limit")
      ->capture_default_str();
  cmd->add_option("--icp-max-distance", o.icp.max_correspondence_m,
                  "ICP: ignore pairs farther apart [m] (0: keep all)")
      ->capture_default_str();
  cmd->add_flag(
      "--accelerate", [&o](std::int64_t) { o.icp.accelerate = true; },
      "Besl-McKay's extrapolation in ICP (off: plain ICP)");
  cmd->add_option("--min-depth", o.min_depth_m, "Depth gate minimum [m] (0: none)")
      ->capture_default_str();
  cmd->add_option("--max-depth", o.max_depth_m, "Depth gate maximum [m] (0: none)")
      ->capture_default_str();
  cmd->add_option("--voxel", o.voxel_m, "Map voxel size [m]")->capture_default_str();
  cmd->add_flag(
      "--no-map", [&o](std::int64_t) { o.write_map = false; }, "Do not build map.ply");
  cmd->add_flag("--threshold-table", o.threshold_table,
                "Segments/planes of the first frame for Lab thresholds 10..30 x angles 15..60");
  cmd->add_option("--depth-factor", o.input.depth_factor,
                  "Depth PNG units per metre (0: dataset's)")
      ->capture_default_str();
  cmd->add_option("--max-frames", o.input.max_frames, "Process at most N frames (0: all)");
  cmd->add_option("--first-frame", o.input.first_frame, "Start at this frame");
  cmd->add_flag("--skip-missing", o.input.skip_missing,
                "Skip listed images whose files are missing");
  cmd->add_option("--seed", o.frame.seed, "Sampling / K-Means seed")->capture_default_str();
  cmd->add_flag("--quiet", o.quiet, "No progress line");
  cmd->callback([options, settings, segmentation, fit, reference, gap, gaps] {
    rgbd::PlanarRunOptions& o = *options;
    if (!settings->empty()) o.input.settings = *settings;
    o.frame.segmentation = rgbd::ParseSegmentationMethod(*segmentation);
    o.frame.fit = rgbd::ParsePlaneFitMethod(*fit);
    if (*reference == "full-icp") {
      o.reference_full_icp = true;
    } else if (*reference != "none") {
      throw OptionError(fmt::format("--reference '{}': none | full-icp", *reference));
    }
    o.gaps = gaps->empty() ? std::vector<int>{*gap} : *gaps;
    const rgbd::PlanarRunResult r = rgbd::RunPlanar(o);
    if (!r.threshold_table.empty()) {
      fmt::print("segments and planes of the first frame:\n{}", rgbd::FormatThresholdTable(r));
    }
    fmt::print("{}", rgbd::FormatGapTable(r));
    fmt::print(
        "wall {:.1f} s; outputs: {}/{{trajectory.txt, trajectory_gap*.txt, map.ply, "
        "pairs.csv, stats.json}}\n",
        r.wall_s, o.out.string());
  });
}

}  // namespace pkslam::apps
