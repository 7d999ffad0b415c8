// `pkslam planar`: seed 001's plane-sampled ICP over a TUM RGB-D folder, with the paper's
// reference (point-to-point ICP on the full clouds) and its experiments:
//   - for every frame gap g in `gaps`, the chain of frames 0, g, 2g, ... is registered pair by
//     pair (source = the later frame's plane samples, target = the earlier frame's, identity
//     start) and chained; with reference_full_icp the same pairs are registered with the full
//     clouds (every full_stride-th pixel);
//   - per gap: total times (segmentation, plane fitting and merging, sampling, ICP; the
//     reference's cloud, k-d tree and ICP), speed-up % = (T_ref - T) / T_ref with and without
//     the segmentation (the paper's "time without segmentation"), per-pair registration error
//     against ground truth, ATE of the chained trajectories, and the model error: RMS distance
//     between the planar and the reference camera positions (the paper compares the two models);
//   - with threshold_table, segments and planes of the first frame for Lab thresholds
//     10..30 and merge angles 15..60 (the paper's Tables 1-2).
// Outputs: OUT/trajectory.txt (the first gap's chain; TUM, world_from_camera, seconds),
// OUT/trajectory_gap<g>.txt and, with the reference, OUT/trajectory_full_icp_gap<g>.txt,
// OUT/map.ply (the first gap's chain, full coloured clouds), OUT/pairs.csv, OUT/stats.json.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "rgbd/icp.h"
#include "rgbd/planar_frame.h"
#include "rgbd/rgbd_sequence.h"

namespace pkslam::rgbd {

struct PlanarRunOptions {
  RgbdSequenceOptions input;
  PlanarFrameOptions frame;
  IcpOptions icp;
  // Frame gaps to run (the paper: 1..5).
  std::vector<int> gaps = {1};
  // Also register with full-point ICP (the paper's reference model).
  bool reference_full_icp = false;
  // The reference uses every full_stride-th pixel in u and v (1 = all, as the paper).
  int full_stride = 1;
  // Depth range kept [m] (0 = no limit; the paper uses every non-zero depth).
  double min_depth_m = 0;
  double max_depth_m = 0;
  // Map voxel [m] and pixel stride for OUT/map.ply.
  double voxel_m = 0.02;
  int map_stride = 2;
  bool write_map = true;
  // Segment/plane counts of the first frame per Lab threshold and merge angle.
  bool threshold_table = false;
  std::filesystem::path out = "out_planar";
  bool quiet = false;

  void Check() const;
};

struct RegistrationTotals {
  int pairs = 0;
  double segmentation_ms = 0;  // planar: all frames of the chain
  double fitting_ms = 0;
  double sampling_ms = 0;
  double icp_ms = 0;    // k-d tree + ICP
  double cloud_ms = 0;  // reference: lifting the full clouds
  double total_ms() const { return segmentation_ms + fitting_ms + sampling_ms + icp_ms + cloud_ms; }
  double without_segmentation_ms() const { return total_ms() - segmentation_ms; }
  double mean_points = 0;  // ICP source points per pair
  double mean_icp_iterations = 0;
  std::vector<double> translation_errors_m;  // per pair vs ground truth (empty without it)
  std::vector<double> rotation_errors_deg;
  std::optional<double> ate_rmse_m;  // chained trajectory vs ground truth (SE(3)-aligned)
};

struct GapResult {
  int gap = 1;
  int frames = 0;            // frames in the chain
  double mean_segments = 0;  // per frame
  double mean_planes = 0;
  double mean_dropped_fraction = 0;
  RegistrationTotals planar;
  std::optional<RegistrationTotals> full;  // with reference_full_icp
  std::optional<double> model_error_m;     // RMS planar-vs-reference camera position distance
  // Per pair: |translation| and angle [deg] of the true motion, i.e. the error of assuming
  // no motion (the floor any registration must beat to be worth running).
  std::vector<double> motion_m;
  std::vector<double> motion_deg;
  // 100 (T_ref - T) / T_ref (with reference_full_icp).
  std::optional<double> speedup_percent;
  std::optional<double> speedup_without_segmentation_percent;
};

struct ThresholdRow {
  double lab_threshold = 0;
  int segments = 0;
  double segmentation_ms = 0;
  std::vector<std::pair<double, int>> planes_per_angle;  // (merge angle, planes)
};

struct PlanarRunResult {
  std::vector<GapResult> gaps;
  std::vector<ThresholdRow> threshold_table;
  double wall_s = 0;
};

PlanarRunResult RunPlanar(const PlanarRunOptions& options);

// The gap table (the paper's Tables 10-15 side by side) and the threshold table as text.
std::string FormatGapTable(const PlanarRunResult& result);
std::string FormatThresholdTable(const PlanarRunResult& result);

}  // namespace pkslam::rgbd
