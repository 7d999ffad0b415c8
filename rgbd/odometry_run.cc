#include "rgbd/odometry_run.h"

#include <fmt/format.h>

#include <chrono>
#include <fstream>

#include "core/util/cpu_time.h"
#include "core/util/error.h"
#include "core/util/json_writer.h"
#include "core/util/log.h"
#include "core/util/output_file.h"
#include "core/util/progress.h"
#include "io/trajectory.h"
#include "rgbd/voxel_map.h"

namespace pkslam::rgbd {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

void WriteStageTimes(JsonWriter& json, const StageTimesMs& t) {
  json.BeginObject();
  json.Member("preprocessing", t.preprocessing);
  json.Member("detection", t.detection);
  json.Member("matching", t.matching);
  json.Member("pose", t.pose);
  json.Member("total", t.total());
  json.EndObject();
}

}  // namespace

void OdometryRunOptions::Check() const {
  input.Check();
  odometry.Check();
  PKSLAM_CHECK_OPTION(voxel_m > 0, "voxel", "{}", voxel_m);
  PKSLAM_CHECK_OPTION(map_stride >= 1, "map_stride", "{}", map_stride);
  PKSLAM_CHECK_OPTION(!out.empty(), "out", "empty output directory");
}

std::string FormatStageTable(const std::string& name, const StageTimesMs& t) {
  std::string s = fmt::format("{:<24} {:>13} {:>10} {:>9} {:>8} {:>9}\n", "per frame [ms]",
                              "preprocessing", "detection", "matching", "pose", "total");
  s += fmt::format("{:<24} {:>13.2f} {:>10.2f} {:>9.2f} {:>8.2f} {:>9.2f}\n", name, t.preprocessing,
                   t.detection, t.matching, t.pose, t.total());
  return s;
}

OdometryRunResult RunRgbdOdometry(const OdometryRunOptions& options) {
  options.Check();
  const auto wall_start = Clock::now();
  const RgbdSequence sequence = OpenRgbdSequence(options.input);
  fs::create_directories(options.out);

  FeatureOdometry odometry(sequence.camera, options.odometry);
  const DepthLifter lifter(sequence.camera);
  VoxelMap map(options.voxel_m);
  Trajectory trajectory;
  OdometryRunResult result;
  StageTimesMs sum_times;
  double sum_matches = 0, sum_inliers = 0, sum_iterations = 0, sum_map_ms = 0;
  int timed = 0;

  std::string frames_csv =
      "t_s,status,keypoints,keypoints_with_depth,matches,inliers,ransac_iterations,"
      "step_rotation_deg,step_translation_m,preprocessing_ms,detection_ms,matching_ms,pose_ms,"
      "total_ms\n";
  Progress progress("rgbd-odometry", sequence.size(), options.quiet);
  for (std::size_t k = 0; k < sequence.size(); ++k) {
    const RgbdFrame frame = LoadRgbdFrame(sequence, k);
    const OdometryStep step = odometry.Process(frame.colour_bgr, frame.depth_m);
    ++result.frames;
    switch (step.status) {
      case OdometryStatus::kFirst:
        break;
      case OdometryStatus::kTracked:
        ++result.tracked;
        break;
      case OdometryStatus::kTooFewMatches:
        ++result.rejected_too_few_matches;
        break;
      case OdometryStatus::kRansacFailed:
        ++result.rejected_ransac;
        break;
      case OdometryStatus::kMotionGate:
        ++result.rejected_motion_gate;
        break;
      case OdometryStatus::kReset:
        ++result.resets;
        break;
    }
    if (step.status != OdometryStatus::kFirst) {
      sum_times.preprocessing += step.times.preprocessing;
      sum_times.detection += step.times.detection;
      sum_times.matching += step.times.matching;
      sum_times.pose += step.times.pose;
      sum_matches += step.matches;
      sum_inliers += step.inliers;
      sum_iterations += step.ransac_iterations;
      ++timed;
    }
    if (HasPose(step.status)) {
      trajectory.poses.push_back({frame.t_ns, step.world_from_camera});
      if (options.write_map) {
        const double map_start = ProcessCpuMs();
        map.AddCloud(LiftDepthImage(step.depth_m, frame.colour_bgr, lifter, options.map_stride),
                     step.world_from_camera);
        sum_map_ms += ProcessCpuMs() - map_start;
      }
    }
    frames_csv += fmt::format(
        "{:.6f},{},{},{},{},{},{},{:.4f},{:.5f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f}\n",
        static_cast<double>(frame.t_ns) * 1e-9, OdometryStatusName(step.status), step.keypoints,
        step.keypoints_with_depth, step.matches, step.inliers, step.ransac_iterations,
        step.step_rotation_deg, step.step_translation_m, step.times.preprocessing,
        step.times.detection, step.times.matching, step.times.pose, step.times.total());
    progress.Add();
  }
  progress.Finish();

  result.poses = static_cast<int>(trajectory.size());
  if (timed > 0) {
    result.mean_times = {sum_times.preprocessing / timed, sum_times.detection / timed,
                         sum_times.matching / timed, sum_times.pose / timed};
    result.mean_matches = sum_matches / timed;
    result.mean_inliers = sum_inliers / timed;
    result.mean_ransac_iterations = sum_iterations / timed;
  }
  if (result.poses > 0) result.mean_map_ms = sum_map_ms / result.poses;
  result.map_points = map.size();

  WriteTrajectoryTum(trajectory, options.out / "trajectory.txt");
  WriteFileAtomically(options.out / "frames.csv", frames_csv);
  if (options.write_map) map.WritePly(options.out / "map.ply");
  if (sequence.ground_truth && trajectory.size() >= 3) {
    EvaluationOptions eval;
    eval.association.max_diff_s = 0.02;  // TUM's evaluate_ate default
    eval.compute_rpe = false;
    result.ate = EvaluateTrajectories(*sequence.ground_truth, trajectory, eval);
  }
  result.wall_s = std::chrono::duration<double>(Clock::now() - wall_start).count();

  JsonWriter json;
  json.BeginObject();
  json.Member("command", "rgbd-odometry");
  json.Member("dataset", options.input.dataset.string());
  json.Member("camera", sequence.camera.ToString());
  json.Member("camera_source", sequence.camera_source);
  json.Key("options").BeginObject();
  json.Member("min_depth_m", options.odometry.depth.min_depth_m);
  json.Member("max_depth_m", options.odometry.depth.max_depth_m);
  json.Member("bilateral_diameter", options.odometry.depth.bilateral_diameter);
  json.Member("orb_features", options.odometry.orb.n_features);
  json.Member("max_matches", options.odometry.max_matches);
  json.Member("cross_check", options.odometry.cross_check);
  json.Member("ransac_threshold_m", options.odometry.ransac.inlier_threshold_m);
  json.Member("ransac_confidence", options.odometry.ransac.confidence);
  json.Member("ransac_min_inliers", options.odometry.ransac.min_inliers);
  json.Member("max_rotation_deg", options.odometry.max_rotation_deg);
  json.Member("max_translation_m", options.odometry.max_translation_m);
  json.Member("voxel_m", options.voxel_m);
  json.Member("map_stride", options.map_stride);
  json.EndObject();
  json.Member("frames", result.frames);
  json.Member("poses", result.poses);
  json.Member("tracked", result.tracked);
  json.Member("rejected_too_few_matches", result.rejected_too_few_matches);
  json.Member("rejected_ransac", result.rejected_ransac);
  json.Member("rejected_motion_gate", result.rejected_motion_gate);
  json.Member("resets", result.resets);
  json.Key("mean_stage_ms");
  WriteStageTimes(json, result.mean_times);
  json.Member("mean_map_ms", result.mean_map_ms);
  json.Member("mean_matches", result.mean_matches);
  json.Member("mean_inliers", result.mean_inliers);
  json.Member("mean_ransac_iterations", result.mean_ransac_iterations);
  json.Member("map_points", static_cast<std::uint64_t>(result.map_points));
  json.Member("wall_s", result.wall_s);
  json.Key("evaluation");
  if (result.ate) {
    WriteEvaluationJson(*result.ate, json);
  } else {
    json.Null();
  }
  json.EndObject();
  WriteFileAtomically(options.out / "stats.json", json.str());
  return result;
}

}  // namespace pkslam::rgbd
