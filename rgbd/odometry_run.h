// `pkslam rgbd-odometry`: seed 000's frame-to-frame pipeline (feature_odometry.h) over a TUM
// RGB-D folder, building the voxel-grid coloured map and writing
//   OUT/trajectory.txt  TUM format, world_from_camera (the first frame's camera is the world),
//                       seconds; frames rejected by RANSAC or the motion gate have no line
//   OUT/map.ply         voxel-grid coloured map (binary PLY)
//   OUT/frames.csv      per frame: status, keypoints, matches, inliers, step, stage times
//   OUT/stats.json      options, counts, mean stage times, map size, ATE (with ground truth)
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "evaluation/evaluate.h"
#include "rgbd/feature_odometry.h"
#include "rgbd/rgbd_sequence.h"

namespace pkslam::rgbd {

struct OdometryRunOptions {
  RgbdSequenceOptions input;
  FeatureOdometryOptions odometry;
  std::filesystem::path out = "out_rgbd";
  // Map voxel size [m] (the thesis: 0.01, 0.05, 0.10).
  double voxel_m = 0.05;
  // Every map_stride-th pixel of tracked frames goes into the map (1 = all).
  int map_stride = 2;
  bool write_map = true;
  bool quiet = false;  // no progress line

  void Check() const;
};

struct OdometryRunResult {
  int frames = 0;
  int tracked = 0;  // kTracked
  int rejected_too_few_matches = 0;
  int rejected_ransac = 0;
  int rejected_motion_gate = 0;
  int resets = 0;
  int poses = 0;            // lines in trajectory.txt
  StageTimesMs mean_times;  // over frames after the first
  double mean_matches = 0;
  double mean_inliers = 0;
  double mean_ransac_iterations = 0;
  double mean_map_ms = 0;
  std::size_t map_points = 0;
  double wall_s = 0;
  std::optional<EvaluationResult> ate;
};

OdometryRunResult RunRgbdOdometry(const OdometryRunOptions& options);

// The thesis's Table 5-3 layout: one row, stages in columns, milliseconds per frame.
std::string FormatStageTable(const std::string& name, const StageTimesMs& times);

}  // namespace pkslam::rgbd
