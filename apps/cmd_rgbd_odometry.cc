// pkslam rgbd-odometry: frame-to-frame RGB-D (Kinect) modelling (rgbd/odometry_run.h).
#include <fmt/format.h>

#include "apps/commands.h"
#include "core/util/error.h"
#include "rgbd/odometry_run.h"

namespace pkslam::apps {

void RegisterRgbdOdometryCommand(CLI::App& app) {
  auto options = std::make_shared<rgbd::OdometryRunOptions>();
  auto settings = std::make_shared<std::string>();
  auto no_cross_check = std::make_shared<bool>(false);
  auto* cmd = app.add_subcommand(
      "rgbd-odometry",
      "Frame-to-frame RGB-D modelling (ORB + RANSAC/SVD, motion gate, voxel map) on a TUM folder");
  auto& o = *options;
  cmd->add_option("--dataset", o.input.dataset, "TUM RGB-D folder (rgb.txt, depth.txt)")
      ->required();
  cmd->add_option("--settings", *settings,
                  "ORB-SLAM3 settings file for the camera (default: DIR/settings.yaml, or TUM's "
                  "calibration for freiburg1/2/3 folders)");
  cmd->add_option("--out", o.out, "Output directory")->capture_default_str();
  cmd->add_option("--voxel", o.voxel_m, "Map voxel size [m] (the Kinect study compared 0.01, 0.05 and 0.10)")
      ->capture_default_str();
  cmd->add_option("--map-stride", o.map_stride, "Pixel stride of the clouds added to the map")
      ->capture_default_str();
  cmd->add_flag(
      "--no-map", [&o](std::int64_t) { o.write_map = false; }, "Do not build map.ply");
  cmd->add_option("--min-depth", o.odometry.depth.min_depth_m, "Depth gate minimum [m]")
      ->capture_default_str();
  cmd->add_option("--max-depth", o.odometry.depth.max_depth_m, "Depth gate maximum [m] (0: none)")
      ->capture_default_str();
  cmd->add_option("--bilateral", o.odometry.depth.bilateral_diameter,
                  "Bilateral filter diameter [px] (0: off)")
      ->capture_default_str();
  cmd->add_option("--features", o.odometry.orb.n_features, "ORB features per frame")
      ->capture_default_str();
  cmd->add_option("--matches", o.odometry.max_matches, "Best matches kept")->capture_default_str();
  cmd->add_flag("--no-cross-check", *no_cross_check,
                "Plain nearest neighbours (as the Kinect study matched) instead of mutual ones");
  cmd->add_option("--ransac-threshold", o.odometry.ransac.inlier_threshold_m, "Inlier distance [m]")
      ->capture_default_str();
  cmd->add_option("--ransac-confidence", o.odometry.ransac.confidence,
                  "p in N = log(1-p)/log(1-w^k)")
      ->capture_default_str();
  cmd->add_option("--min-inliers", o.odometry.ransac.min_inliers, "Fewer inliers reject the frame")
      ->capture_default_str();
  cmd->add_option("--max-rotation", o.odometry.max_rotation_deg,
                  "Motion gate: rotation per step [deg]")
      ->capture_default_str();
  cmd->add_option("--max-translation", o.odometry.max_translation_m,
                  "Motion gate: translation per step [m]")
      ->capture_default_str();
  cmd->add_option("--depth-factor", o.input.depth_factor,
                  "Depth PNG units per metre (0: dataset's)")
      ->capture_default_str();
  cmd->add_option("--max-frames", o.input.max_frames, "Process at most N frames (0: all)");
  cmd->add_option("--first-frame", o.input.first_frame, "Start at this frame");
  cmd->add_flag("--skip-missing", o.input.skip_missing,
                "Skip listed images whose files are missing");
  cmd->add_flag("--quiet", o.quiet, "No progress line");
  cmd->callback([options, settings, no_cross_check] {
    rgbd::OdometryRunOptions& o = *options;
    if (!settings->empty()) o.input.settings = *settings;
    o.odometry.cross_check = !*no_cross_check;
    const rgbd::OdometryRunResult r = rgbd::RunRgbdOdometry(o);
    fmt::print(
        "frames {} poses {} tracked {} rejected: matches {} ransac {} motion-gate {} resets {}\n",
        r.frames, r.poses, r.tracked, r.rejected_too_few_matches, r.rejected_ransac,
        r.rejected_motion_gate, r.resets);
    fmt::print("mean matches {:.1f} inliers {:.1f} RANSAC iterations {:.1f}\n", r.mean_matches,
               r.mean_inliers, r.mean_ransac_iterations);
    fmt::print("{}", rgbd::FormatStageTable(o.input.dataset.filename().string(), r.mean_times));
    fmt::print("map: {} points (voxel {} m), {:.2f} ms/frame to build; wall {:.1f} s\n",
               r.map_points, o.voxel_m, r.mean_map_ms, r.wall_s);
    if (r.ate) {
      fmt::print("ATE (SE(3)-aligned, {} pairs): rmse {:.4f} m, mean {:.4f} m, max {:.4f} m\n",
                 r.ate->pairs.size(), r.ate->ate_translation_m.rmse, r.ate->ate_translation_m.mean,
                 r.ate->ate_translation_m.max);
    }
    fmt::print("outputs: {}/{{trajectory.txt, map.ply, frames.csv, stats.json}}\n", o.out.string());
  });
}

}  // namespace pkslam::apps
