#include "rgbd/planar_run.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>

#include "core/util/cpu_time.h"
#include "core/util/error.h"
#include "core/util/json_writer.h"
#include "core/util/log.h"
#include "core/util/output_file.h"
#include "core/util/progress.h"
#include "evaluation/evaluate.h"
#include "evaluation/statistics.h"
#include "io/trajectory.h"
#include "rgbd/voxel_map.h"

namespace pkslam::rgbd {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double MsSince(double start_cpu_ms) { return ProcessCpuMs() - start_cpu_ms; }

cv::Mat GateDepth(const cv::Mat& depth_m, double min_m, double max_m) {
  if (min_m <= 0 && max_m <= 0) return depth_m;
  cv::Mat gated = depth_m.clone();
  gated.setTo(0.0f, depth_m < min_m);
  if (max_m > 0) gated.setTo(0.0f, depth_m > max_m);
  return gated;
}

std::optional<double> AteRmse(const std::optional<Trajectory>& truth, const Trajectory& estimate) {
  if (!truth || estimate.size() < 3) return std::nullopt;
  EvaluationOptions eval;
  eval.association.max_diff_s = 0.02;
  eval.compute_rpe = false;
  return EvaluateTrajectories(*truth, estimate, eval).ate_translation_m.rmse;
}

double Rms(const std::vector<double>& v) {
  if (v.empty()) return 0;
  double s = 0;
  for (const double x : v) s += x * x;
  return std::sqrt(s / static_cast<double>(v.size()));
}

double Max(const std::vector<double>& v) {
  return v.empty() ? 0 : *std::max_element(v.begin(), v.end());
}

double Mean(const std::vector<double>& v) {
  if (v.empty()) return 0;
  double s = 0;
  for (const double x : v) s += x;
  return s / static_cast<double>(v.size());
}

void WriteTotals(JsonWriter& json, const RegistrationTotals& t) {
  json.BeginObject();
  json.Member("pairs", t.pairs);
  json.Member("segmentation_ms", t.segmentation_ms);
  json.Member("fitting_ms", t.fitting_ms);
  json.Member("sampling_ms", t.sampling_ms);
  json.Member("cloud_ms", t.cloud_ms);
  json.Member("icp_ms", t.icp_ms);
  json.Member("total_ms", t.total_ms());
  json.Member("without_segmentation_ms", t.without_segmentation_ms());
  json.Member("mean_icp_points", t.mean_points);
  json.Member("mean_icp_iterations", t.mean_icp_iterations);
  if (!t.translation_errors_m.empty()) {
    json.Member("pair_translation_error_mean_m", Mean(t.translation_errors_m));
    json.Member("pair_translation_error_rms_m", Rms(t.translation_errors_m));
    json.Member("pair_translation_error_max_m", Max(t.translation_errors_m));
    json.Member("pair_rotation_error_mean_deg", Mean(t.rotation_errors_deg));
    json.Member("pair_rotation_error_max_deg", Max(t.rotation_errors_deg));
  }
  json.Key("ate_rmse_m");
  if (t.ate_rmse_m) {
    json.Value(*t.ate_rmse_m);
  } else {
    json.Null();
  }
  json.EndObject();
}

// One registration chain for one gap.
struct ChainState {
  std::optional<PointCloudIndex> planar_target;  // previous frame's samples
  std::optional<PointCloudIndex> full_target;    // previous frame's full cloud
  SE3d world_from_planar;
  SE3d world_from_full;
  std::optional<SE3d> world_from_truth_previous;
};

}  // namespace

void PlanarRunOptions::Check() const {
  input.Check();
  frame.Check();
  icp.Check();
  PKSLAM_CHECK_OPTION(!gaps.empty(), "gaps", "no gap given");
  for (const int g : gaps) PKSLAM_CHECK_OPTION(g >= 1, "gap", "{}", g);
  PKSLAM_CHECK_OPTION(full_stride >= 1, "full_stride", "{}", full_stride);
  PKSLAM_CHECK_OPTION(min_depth_m >= 0 && max_depth_m >= 0, "depth range", "{}..{}", min_depth_m,
                      max_depth_m);
  PKSLAM_CHECK_OPTION(max_depth_m == 0 || max_depth_m > min_depth_m, "max_depth", "{} <= {}",
                      max_depth_m, min_depth_m);
  PKSLAM_CHECK_OPTION(voxel_m > 0, "voxel", "{}", voxel_m);
  PKSLAM_CHECK_OPTION(map_stride >= 1, "map_stride", "{}", map_stride);
}

namespace {

std::vector<ThresholdRow> ThresholdTable(const RgbdSequence& sequence, const DepthLifter& lifter,
                                         const PlanarRunOptions& options) {
  const RgbdFrame frame = LoadRgbdFrame(sequence, 0);
  const cv::Mat depth = GateDepth(frame.depth_m, options.min_depth_m, options.max_depth_m);
  std::vector<ThresholdRow> rows;
  for (const double threshold : {10.0, 15.0, 20.0, 25.0, 30.0}) {
    ThresholdRow row;
    row.lab_threshold = threshold;
    for (const double angle : {15.0, 30.0, 45.0, 60.0}) {
      PlanarFrameOptions o = options.frame;
      o.segmentation = SegmentationMethod::kRegionGrowing;
      o.lab_threshold = threshold;
      o.merge_angle_deg = angle;
      const PlanarFrame planar = BuildPlanarFrame(frame.colour_bgr, depth, lifter, o);
      row.segments = planar.segments;
      row.segmentation_ms = angle == 15.0 ? planar.segmentation_ms
                                          : std::min(row.segmentation_ms, planar.segmentation_ms);
      row.planes_per_angle.emplace_back(angle, planar.planes);
    }
    rows.push_back(row);
  }
  return rows;
}

GapResult RunGap(const RgbdSequence& sequence, const DepthLifter& lifter,
                 const PlanarRunOptions& options, int gap, bool write_outputs, Progress* progress,
                 std::string* pairs_csv) {
  GapResult result;
  result.gap = gap;
  ChainState chain;
  Trajectory planar_trajectory, full_trajectory;
  RegistrationTotals planar, full;
  VoxelMap map(options.voxel_m);
  std::vector<double> model_differences;
  double sum_segments = 0, sum_planes = 0, sum_dropped = 0, sum_planar_points = 0,
         sum_full_points = 0, sum_planar_iterations = 0, sum_full_iterations = 0;

  for (std::size_t k = 0; k < sequence.size(); k += static_cast<std::size_t>(gap)) {
    const RgbdFrame frame = LoadRgbdFrame(sequence, k);
    const cv::Mat depth = GateDepth(frame.depth_m, options.min_depth_m, options.max_depth_m);
    const std::optional<SE3d> truth =
        sequence.ground_truth ? InterpolatePose(*sequence.ground_truth, frame.t_ns) : std::nullopt;

    // --- planar: segmentation, planes, samples; ICP against the previous frame ---
    const PlanarFrame planar_frame =
        BuildPlanarFrame(frame.colour_bgr, depth, lifter, options.frame);
    planar.segmentation_ms += planar_frame.segmentation_ms;
    planar.fitting_ms += planar_frame.fitting_ms;
    planar.sampling_ms += planar_frame.sampling_ms;
    sum_segments += planar_frame.segments;
    sum_planes += planar_frame.planes;
    sum_dropped += planar_frame.dropped_fraction;
    double start = ProcessCpuMs();
    PointCloudIndex planar_index(planar_frame.samples);
    std::optional<SE3d> planar_step;
    if (chain.planar_target) {
      const IcpResult icp =
          IcpPointToPoint(planar_frame.samples, *chain.planar_target, SE3d(), options.icp);
      if (icp.success) planar_step = icp.target_from_source;
      sum_planar_iterations += icp.iterations;
      sum_planar_points += static_cast<double>(planar_frame.samples.size());
    }
    planar.icp_ms += MsSince(start);
    chain.planar_target = std::move(planar_index);

    // --- reference: full-point ICP ---
    std::optional<SE3d> full_step;
    if (options.reference_full_icp) {
      start = ProcessCpuMs();
      ColouredCloud cloud = LiftDepthImage(depth, cv::Mat(), lifter, options.full_stride);
      full.cloud_ms += MsSince(start);
      start = ProcessCpuMs();
      std::vector<Eigen::Vector3f> points = std::move(cloud.points);
      if (chain.full_target) {
        const IcpResult icp = IcpPointToPoint(points, *chain.full_target, SE3d(), options.icp);
        if (icp.success) full_step = icp.target_from_source;
        sum_full_iterations += icp.iterations;
        sum_full_points += static_cast<double>(points.size());
      }
      chain.full_target.emplace(std::move(points));
      full.icp_ms += MsSince(start);
    }

    // --- chaining and errors ---
    const bool first = k == 0;
    if (!first) {
      ++planar.pairs;
      if (options.reference_full_icp) ++full.pairs;
      // A failed registration (too few pairs) keeps the previous pose: counted as an error.
      chain.world_from_planar = chain.world_from_planar * planar_step.value_or(SE3d());
      if (options.reference_full_icp)
        chain.world_from_full = chain.world_from_full * full_step.value_or(SE3d());
      if (truth && chain.world_from_truth_previous) {
        const SE3d truth_step = chain.world_from_truth_previous->Inverse() * *truth;
        result.motion_m.push_back(truth_step.translation().norm());
        result.motion_deg.push_back(truth_step.so3().Angle() * 180.0 / M_PI);
        const auto e = CompareRelativePose(planar_step.value_or(SE3d()), truth_step);
        planar.translation_errors_m.push_back(e.translation_m);
        planar.rotation_errors_deg.push_back(e.rotation_deg);
        if (options.reference_full_icp) {
          const auto f = CompareRelativePose(full_step.value_or(SE3d()), truth_step);
          full.translation_errors_m.push_back(f.translation_m);
          full.rotation_errors_deg.push_back(f.rotation_deg);
        }
      }
      *pairs_csv += fmt::format(
          "{},{},{:.6f},{},{},{:.3f},{:.3f}", gap, k, static_cast<double>(frame.t_ns) * 1e-9,
          planar_frame.planes, planar_frame.samples.size(), planar_frame.time_ms(),
          planar.translation_errors_m.empty() ? NAN : planar.translation_errors_m.back());
      *pairs_csv += options.reference_full_icp && !full.translation_errors_m.empty()
                        ? fmt::format(",{:.6f}\n", full.translation_errors_m.back())
                        : std::string(",\n");
    }
    chain.world_from_truth_previous = truth;
    planar_trajectory.poses.push_back({frame.t_ns, chain.world_from_planar});
    if (options.reference_full_icp) {
      full_trajectory.poses.push_back({frame.t_ns, chain.world_from_full});
      model_differences.push_back(
          (chain.world_from_planar.translation() - chain.world_from_full.translation()).norm());
    }
    if (write_outputs && options.write_map) {
      map.AddCloud(LiftDepthImage(depth, frame.colour_bgr, lifter, options.map_stride),
                   chain.world_from_planar);
    }
    ++result.frames;
    progress->Add();
  }

  const double n = std::max(1, result.frames);
  result.mean_segments = sum_segments / n;
  result.mean_planes = sum_planes / n;
  result.mean_dropped_fraction = sum_dropped / n;
  if (planar.pairs > 0) {
    planar.mean_points = sum_planar_points / planar.pairs;
    planar.mean_icp_iterations = sum_planar_iterations / planar.pairs;
  }
  planar.ate_rmse_m = AteRmse(sequence.ground_truth, planar_trajectory);
  WriteTrajectoryTum(planar_trajectory, options.out / fmt::format("trajectory_gap{}.txt", gap));
  if (write_outputs) {
    WriteTrajectoryTum(planar_trajectory, options.out / "trajectory.txt");
    if (options.write_map) map.WritePly(options.out / "map.ply");
  }
  result.planar = planar;
  if (options.reference_full_icp) {
    if (full.pairs > 0) {
      full.mean_points = sum_full_points / full.pairs;
      full.mean_icp_iterations = sum_full_iterations / full.pairs;
    }
    full.ate_rmse_m = AteRmse(sequence.ground_truth, full_trajectory);
    WriteTrajectoryTum(full_trajectory,
                       options.out / fmt::format("trajectory_full_icp_gap{}.txt", gap));
    result.full = full;
    result.model_error_m = Rms(model_differences);
    if (full.total_ms() > 0) {
      result.speedup_percent = 100.0 * (full.total_ms() - planar.total_ms()) / full.total_ms();
      result.speedup_without_segmentation_percent =
          100.0 * (full.total_ms() - planar.without_segmentation_ms()) / full.total_ms();
    }
  }
  return result;
}

void WriteStats(const PlanarRunOptions& options, const RgbdSequence& sequence,
                const PlanarRunResult& result) {
  JsonWriter json;
  json.BeginObject();
  json.Member("command", "planar");
  json.Member("dataset", options.input.dataset.string());
  json.Member("camera", sequence.camera.ToString());
  json.Member("frames", static_cast<std::uint64_t>(sequence.size()));
  json.Key("options").BeginObject();
  json.Member("segmentation", SegmentationMethodName(options.frame.segmentation));
  json.Member("lab_threshold", options.frame.lab_threshold);
  json.Member("kmeans_clusters", options.frame.kmeans_clusters);
  json.Member("plane_fit", PlaneFitMethodName(options.frame.fit));
  json.Member("merge_angle_deg", options.frame.merge_angle_deg);
  json.Member("merge_max_fit_rms_m", options.frame.merge_max_fit_rms_m);
  json.Member("samples_per_plane", options.frame.samples_per_plane);
  json.Member("min_sampled_plane_points", options.frame.min_sampled_plane_points);
  json.Member("icp_max_iterations", options.icp.max_iterations);
  json.Member("icp_max_correspondence_m", options.icp.max_correspondence_m);
  json.Member("icp_accelerate", options.icp.accelerate);
  json.Member("reference_full_icp", options.reference_full_icp);
  json.Member("full_stride", options.full_stride);
  json.Member("min_depth_m", options.min_depth_m);
  json.Member("max_depth_m", options.max_depth_m);
  json.EndObject();
  json.Key("gaps").BeginArray();
  for (const GapResult& g : result.gaps) {
    json.BeginObject();
    json.Member("gap", g.gap);
    json.Member("frames", g.frames);
    json.Member("mean_segments", g.mean_segments);
    json.Member("mean_planes", g.mean_planes);
    json.Member("mean_dropped_fraction", g.mean_dropped_fraction);
    if (!g.motion_m.empty()) {
      json.Member("mean_motion_m", Mean(g.motion_m));
      json.Member("mean_motion_deg", Mean(g.motion_deg));
    }
    json.Key("planar");
    WriteTotals(json, g.planar);
    json.Key("full_icp");
    if (g.full) {
      WriteTotals(json, *g.full);
    } else {
      json.Null();
    }
    json.Key("speedup_percent");
    g.speedup_percent ? json.Value(*g.speedup_percent) : json.Null();
    json.Key("speedup_without_segmentation_percent");
    g.speedup_without_segmentation_percent ? json.Value(*g.speedup_without_segmentation_percent)
                                           : json.Null();
    json.Key("model_error_m");
    g.model_error_m ? json.Value(*g.model_error_m) : json.Null();
    json.EndObject();
  }
  json.EndArray();
  json.Key("threshold_table").BeginArray();
  for (const ThresholdRow& row : result.threshold_table) {
    json.BeginObject();
    json.Member("lab_threshold", row.lab_threshold);
    json.Member("segments", row.segments);
    json.Member("segmentation_ms", row.segmentation_ms);
    json.Key("planes_per_merge_angle").BeginObject();
    for (const auto& [angle, planes] : row.planes_per_angle)
      json.Member(fmt::format("{:g}", angle), planes);
    json.EndObject();
    json.EndObject();
  }
  json.EndArray();
  json.Member("wall_s", result.wall_s);
  json.EndObject();
  WriteFileAtomically(options.out / "stats.json", json.str());
}

}  // namespace

PlanarRunResult RunPlanar(const PlanarRunOptions& options) {
  options.Check();
  const auto wall_start = Clock::now();
  const RgbdSequence sequence = OpenRgbdSequence(options.input);
  fs::create_directories(options.out);
  const DepthLifter lifter(sequence.camera);
  PlanarRunResult result;
  if (options.threshold_table) result.threshold_table = ThresholdTable(sequence, lifter, options);

  std::size_t steps = 0;
  for (const int g : options.gaps) steps += (sequence.size() + g - 1) / g;
  Progress progress("planar", steps, options.quiet);
  std::string pairs_csv =
      "gap,frame,t_s,planes,samples,planar_frame_ms,planar_error_m,full_icp_error_m\n";
  for (std::size_t i = 0; i < options.gaps.size(); ++i) {
    result.gaps.push_back(
        RunGap(sequence, lifter, options, options.gaps[i], i == 0, &progress, &pairs_csv));
  }
  progress.Finish();
  WriteFileAtomically(options.out / "pairs.csv", pairs_csv);
  result.wall_s = std::chrono::duration<double>(Clock::now() - wall_start).count();
  WriteStats(options, sequence, result);
  return result;
}

std::string FormatGapTable(const PlanarRunResult& result) {
  std::string s = fmt::format(
      "{:>3} {:>5} {:>7} {:>7} {:>7} | {:>10} {:>10} {:>10} {:>8} {:>8} | {:>8} {:>8} {:>8} "
      "{:>8} | {:>8} {:>8} {:>8}\n",
      "gap", "pairs", "planes", "samples", "full pts", "planar[s]", "w/o seg[s]", "full[s]",
      "speedup%", "w/o seg%", "motion", "err[cm]", "max[cm]", "full[cm]", "ATE[cm]", "fullATE",
      "model");
  const auto cm = [](double m) { return fmt::format("{:.2f}", 100 * m); };
  for (const GapResult& g : result.gaps) {
    const bool gt = !g.planar.translation_errors_m.empty();
    s += fmt::format(
        "{:>3} {:>5} {:>7.0f} {:>7.0f} {:>7} | {:>10.3f} {:>10.3f} {:>10} {:>8} {:>8} | {:>8} "
        "{:>8} {:>8} {:>8} | {:>8} {:>8} {:>8}\n",
        g.gap, g.planar.pairs, g.mean_planes, g.planar.mean_points,
        g.full ? fmt::format("{:.0f}", g.full->mean_points) : "-", g.planar.total_ms() / 1000,
        g.planar.without_segmentation_ms() / 1000,
        g.full ? fmt::format("{:.3f}", g.full->total_ms() / 1000) : "-",
        g.speedup_percent ? fmt::format("{:.1f}", *g.speedup_percent) : "-",
        g.speedup_without_segmentation_percent
            ? fmt::format("{:.1f}", *g.speedup_without_segmentation_percent)
            : "-",
        gt ? cm(Mean(g.motion_m)) : "-", gt ? cm(Mean(g.planar.translation_errors_m)) : "-",
        gt ? cm(Max(g.planar.translation_errors_m)) : "-",
        g.full && gt ? cm(Mean(g.full->translation_errors_m)) : "-",
        g.planar.ate_rmse_m ? cm(*g.planar.ate_rmse_m) : "-",
        g.full && g.full->ate_rmse_m ? cm(*g.full->ate_rmse_m) : "-",
        g.model_error_m ? cm(*g.model_error_m) : "-");
  }
  s += "planes: per frame; samples / full pts: ICP source points per pair (planar / full);\n"
       "times: CPU s over the chain; motion: mean true step (the error of assuming no motion);\n"
       "err/max: per-pair translation error vs ground truth (mean/max), full: the same for\n"
       "full-point ICP, ATE: chained trajectory RMSE (SE(3)-aligned), model: RMS distance\n"
       "between planar and full-ICP camera positions; speed-up = (T_full - T) / T_full.\n";
  return s;
}

std::string FormatThresholdTable(const PlanarRunResult& result) {
  if (result.threshold_table.empty()) return {};
  std::string s = fmt::format("{:>9} {:>9} {:>8}", "Lab thr", "segments", "seg[ms]");
  for (const auto& [angle, planes] : result.threshold_table.front().planes_per_angle) {
    s += fmt::format(" {:>9}", fmt::format("planes@{:g}", angle));
  }
  s += "\n";
  for (const ThresholdRow& row : result.threshold_table) {
    s += fmt::format("{:>9.0f} {:>9} {:>8.1f}", row.lab_threshold, row.segments,
                     row.segmentation_ms);
    for (const auto& [angle, planes] : row.planes_per_angle) s += fmt::format(" {:>9}", planes);
    s += "\n";
  }
  return s;
}

}  // namespace pkslam::rgbd
