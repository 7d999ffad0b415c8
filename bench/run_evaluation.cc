#include "bench/run_evaluation.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <map>
#include <type_traits>

#include "bench/bias_evaluation.h"
#include "core/util/error.h"
#include "core/util/log.h"
#include "evaluation/evaluate.h"
#include "evaluation/evaluation_output.h"
#include "io/json_file.h"
#include "io/rigid_transform_file.h"
#include "io/trajectory.h"
#include "viewer/view_data.h"
#include "viewer/view_html.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

struct StatsJson {
  int frames = 0;
  int keyframes = 0;
  int map_points = 0;
  int lost_frames = 0;
  double wall_s = kNaN;
  double median_tracking_ms = kNaN;
  // Optional (older pkslam versions and peers write fewer keys): NaN when absent.
  double realtime_factor = kNaN;
  double p95_tracking_ms = kNaN;
  double mapping_ms_per_kf = kNaN;
  double cpu_s = kNaN;
  double peak_memory_mib = kNaN;
  double sequence_s = kNaN;
  double mapping_cpu_s = kNaN;
  double degraded = kNaN;
  double suspect = kNaN;
  std::string keyframe_reasons;  // "reason=count ..."
  double keyframes_created = kNaN;
};

// realtime_factor from stats.json, else sequence_duration_s / wall time. A factor <= 0 is
// what `pkslam run` writes when it measured no wall time: not a measure.
double RealtimeFactor(double written, double sequence_s, double wall_s) {
  const double factor = std::isfinite(written) ? written : sequence_s / wall_s;
  return std::isfinite(factor) && factor > 0 ? factor : kNaN;
}

// stats.json is plain JSON, which yaml-cpp reads as YAML flow style.
StatsJson ReadStats(const fs::path& file) {
  if (!fs::exists(file)) throw InputError(file, "missing (the run did not finish)");
  const YAML::Node root = ReadJsonFile(file);
  auto get = [&](const char* key, auto fallback) {
    using T = decltype(fallback);
    if (!root[key]) throw InputError(file, std::string("no '") + key + "' field");
    // A measure the run could not take is null (JSON has no NaN).
    if constexpr (std::is_floating_point_v<T>) {
      if (root[key].IsNull()) return static_cast<T>(kNaN);
    }
    try {
      return root[key].as<T>();
    } catch (const YAML::Exception&) {
      throw InputError(file, root[key].Mark().line + 1, std::string("bad '") + key + "'");
    }
  };
  auto optional = [&](const char* key) { return root[key] ? get(key, 0.0) : kNaN; };
  StatsJson s;
  s.frames = get("frames", 0);
  s.keyframes = get("keyframes", 0);
  s.keyframes_created = optional("keyframes_created");
  s.map_points = get("map_points", 0);
  s.lost_frames = get("lost_frames", 0);
  s.wall_s = get("wall_time_s", 0.0);
  s.median_tracking_ms = get("median_tracking_ms", 0.0);
  s.realtime_factor =
      RealtimeFactor(optional("realtime_factor"), optional("sequence_duration_s"), s.wall_s);
  s.p95_tracking_ms = optional("p95_tracking_ms");
  s.mapping_ms_per_kf = optional("median_local_mapping_ms");
  s.cpu_s = optional("process_cpu_s");
  s.peak_memory_mib = optional("peak_memory_mib");
  s.sequence_s = optional("sequence_duration_s");
  s.mapping_cpu_s = optional("local_mapping_cpu_s");
  if (root["degraded"]) s.degraded = get("degraded", false) ? 1.0 : 0.0;
  // system/estimate_health.h; stats.json files from before it carry the losses for good only.
  const YAML::Node estimate = root["estimate"];
  const YAML::Node loops = root["loop_closing"];
  if (estimate && estimate.IsMap() && estimate["suspect"]) {
    try {
      s.suspect = estimate["suspect"].as<bool>() ? 1.0 : 0.0;
    } catch (const YAML::Exception&) {
      throw InputError(file, estimate["suspect"].Mark().line + 1, "bad 'estimate.suspect'");
    }
  } else if (loops && loops.IsMap() && loops["new_map_or_reset_times_s"] &&
             loops["new_map_or_reset_times_s"].IsSequence()) {
    s.suspect = loops["new_map_or_reset_times_s"].size() > 0 ? 1.0 : 0.0;
  }
  if (const YAML::Node reasons = root["keyframe_reasons"]; reasons && reasons.IsMap()) {
    for (const auto& kv : reasons) {
      if (!s.keyframe_reasons.empty()) s.keyframe_reasons += ' ';
      s.keyframe_reasons += kv.first.as<std::string>() + "=" + kv.second.as<std::string>();
    }
  }
  return s;
}

void WritePlotFiles(const fs::path& dir, const Trajectory& gt, const Trajectory& est,
                    const Trajectory& keyframes, const EvaluationResult& primary) {
  std::ofstream traj(dir / "plot_trajectory.csv", std::ios::trunc);
  traj << "t_s,gt_x,gt_y,gt_z,est_x,est_y,est_z\n";
  for (const auto& [i_ref, i_est] : primary.pairs) {
    const Eigen::Vector3d g = gt.poses[i_ref].pose.translation();
    const Eigen::Vector3d e = primary.ref_from_est * est.poses[i_est].pose.translation();
    traj << fmt::format("{:.6f},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f},{:.5f}\n",
                        1e-9 * static_cast<double>(gt.poses[i_ref].t_ns), g.x(), g.y(), g.z(),
                        e.x(), e.y(), e.z());
  }
  std::ofstream kf(dir / "plot_keyframes.csv", std::ios::trunc);
  kf << "t_s,x,y,z\n";
  // keyframes.txt holds camera poses; the estimate the ground truth is compared with may be
  // the body's. A keyframe is also a tracked frame with the same timestamp and pose, so take
  // its position from the estimate (the camera's when the frame is absent).
  std::map<std::int64_t, std::size_t> est_index;
  for (std::size_t i = 0; i < est.poses.size(); ++i) est_index[est.poses[i].t_ns] = i;
  for (const auto& p : keyframes.poses) {
    const auto it = est_index.find(p.t_ns);
    const Eigen::Vector3d position =
        it != est_index.end() ? est.poses[it->second].pose.translation() : p.pose.translation();
    const Eigen::Vector3d e = primary.ref_from_est * position;
    kf << fmt::format("{:.6f},{:.5f},{:.5f},{:.5f}\n", 1e-9 * static_cast<double>(p.t_ns), e.x(),
                      e.y(), e.z());
  }
  if (!traj || !kf) throw Error("cannot write plot files in " + dir.string());
}

}  // namespace

namespace {

// RUN/view.html (`pkslam view`), its scripts shared in the bench folder's viewer/ (the parent
// of runs/). A page that cannot be made (no libjs-three) costs a warning, not the run.
void WriteRunView(const fs::path& run_dir, const fs::path& gt_file) {
  try {
    fs::path out = run_dir;
    while (!out.empty() && out.filename() != "runs" && out != out.root_path()) {
      out = out.parent_path();
    }
    ViewPageOptions page;
    if (out.filename() == "runs") {
      const fs::path scripts = out.parent_path() / "viewer";
      if (!fs::exists(scripts / "viewer.js")) CopyViewScripts(scripts, page);
      page.shared_scripts = fs::relative(scripts, run_dir);
    }
    ViewOptions view;
    view.run = run_dir;
    view.ground_truth = gt_file;
    view.max_map_points = 50000;
    WriteViewPage(LoadViewData(view), run_dir / "view.html", page);
  } catch (const Error& e) {
    PKSLAM_LOG_WARN("no viewer page for {}: {}", run_dir.string(), e.what());
  }
}

}  // namespace

fs::path FindGroundTruth(const fs::path& dataset) {
  if (auto file = FindDatasetGroundTruth(dataset)) return *file;
  throw InputError(dataset,
                   "no ground truth (mav0/state_groundtruth_estimate0/data.csv or groundtruth.txt);"
                   " set the dataset's ground_truth in the suite");
}

void EvaluateRun(const RunFiles& files, RunResult* result) {
  const StatsJson stats = ReadStats(files.run_dir / "stats.json");
  result->frames = stats.frames;
  result->keyframes = stats.keyframes;
  result->map_points = stats.map_points;
  result->lost_frames = stats.lost_frames;
  result->wall_s = stats.wall_s;
  result->median_tracking_ms = stats.median_tracking_ms;
  result->realtime_factor = stats.realtime_factor;
  result->p95_tracking_ms = stats.p95_tracking_ms;
  result->mapping_ms_per_kf = stats.mapping_ms_per_kf;
  result->cpu_s = stats.cpu_s;
  result->peak_memory_mib = stats.peak_memory_mib;
  result->sequence_s = stats.sequence_s;
  result->mapping_cpu_s = stats.mapping_cpu_s;
  result->degraded = stats.degraded;
  result->suspect = stats.suspect;
  result->keyframe_reasons = stats.keyframe_reasons;
  result->keyframes_created = stats.keyframes_created;

  const fs::path gt_file =
      files.ground_truth ? *files.ground_truth : FindGroundTruth(files.dataset);
  // Visual-only monocular maps have no metric scale: their camera poses are compared with the
  // ground truth moved into the camera (io/rigid_transform_file.h).
  const RunAndGroundTruth pair =
      ReadRunAndGroundTruth(files.run_dir, gt_file, result->sensor == "mono");
  const Trajectory& gt = pair.ground_truth;
  const Trajectory& est = pair.estimate;
  const Trajectory keyframes =
      ReadTrajectory(files.run_dir / "keyframes.txt", TrajectoryFormat::kTum);

  EvaluationOptions options;
  options.compute_rpe = false;
  // The bench picks the file that matches the ground truth's frame itself (trajectory_body.txt,
  // or camera poses against the truth moved into the camera): an orientation offset left here
  // is the estimate's error, measured and counted like any other, not a user's mix-up.
  options.allow_frame_offset = true;
  options.alignment = AlignmentMethod::kSE3;
  const EvaluationResult se3 = EvaluateTrajectories(gt, est, options);
  options.alignment = AlignmentMethod::kSim3;
  const EvaluationResult sim3 = EvaluateTrajectories(gt, est, options);

  result->ate_se3_m = se3.ate_translation_m.rmse;
  result->ate_sim3_m = sim3.ate_translation_m.rmse;
  result->scale = sim3.scale();
  const bool use_sim3 = result->alignment == "sim3";
  result->ate_m = use_sim3 ? result->ate_sim3_m : result->ate_se3_m;
  // RPE is scale dependent: measured after the primary alignment (Sim(3) for monocular runs).
  // A path shorter than the RPE distance has no pose pair: RPE stays empty (NaN).
  options.alignment = use_sim3 ? AlignmentMethod::kSim3 : AlignmentMethod::kSE3;
  options.compute_rpe = true;
  options.rpe.delta = files.rpe_delta_m;
  options.rpe.unit = RpeUnit::kMeters;
  // Every pose starts a pair (evo --all_pairs), as the bench has always measured: over a
  // metre, consecutive pairs would leave a few dozen per run.
  options.rpe.all_pairs = true;
  // rpg's relative error over 10-50% of the path, per pair, for the report's box plots.
  options.compute_segments = true;
  try {
    const EvaluationResult with_rpe = EvaluateTrajectories(gt, est, options);
    result->rpe_trans_m = with_rpe.rpe->translation_m.rmse;
    result->rpe_rot_deg = with_rpe.rpe->rotation_deg.rmse;
    WriteSegmentErrorsCsv(files.run_dir / "segment_errors.csv", est, with_rpe);
  } catch (const OptionError&) {
  }
  result->coverage = stats.frames > 0 ? static_cast<double>(se3.pairs.size()) / stats.frames : 0.0;
  if (const auto bias = EvaluateBiases(files.run_dir / "keyframes_imu.csv", gt, 15.0)) {
    result->gyro_bias_err_pct = bias->gyro_pct;
    result->accel_bias_err_pct = bias->accel_pct;
  }
  WritePlotFiles(files.run_dir, gt, est, keyframes, use_sim3 ? sim3 : se3);
  WriteRunView(files.run_dir, gt_file);
  result->ok = true;
  result->error.clear();
}

}  // namespace pkslam::bench
