#include "evaluation/evaluate.h"

#include <fmt/format.h>

#include <cmath>

#include "core/util/error.h"

namespace pkslam {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

std::filesystem::path NameForMessages(const Trajectory& trajectory, const char* fallback) {
  return trajectory.source.empty() ? std::filesystem::path(fallback) : trajectory.source;
}

std::string TimeRange(const Trajectory& trajectory) {
  return fmt::format("{:.3f}..{:.3f} s", static_cast<double>(trajectory.poses.front().t_ns) * 1e-9,
                     static_cast<double>(trajectory.poses.back().t_ns) * 1e-9);
}

void WriteStatistics(const ErrorStatistics& s, JsonWriter& json) {
  json.BeginObject()
      .Member("rmse", s.rmse)
      .Member("mean", s.mean)
      .Member("median", s.median)
      .Member("std", s.std)
      .Member("min", s.min)
      .Member("max", s.max)
      .Member("sse", s.sse)
      .EndObject();
}

std::string StatisticsRow(std::string_view label, const ErrorStatistics& s) {
  return fmt::format(
      "{:<14} {:>10.6f} {:>10.6f} {:>10.6f} {:>10.6f} {:>10.6f} {:>10.6f} {:>11.6f}\n", label,
      s.rmse, s.mean, s.median, s.std, s.min, s.max, s.sse);
}

}  // namespace

void EvaluationOptions::Check() const {
  association.Check();
  if (compute_rpe) rpe.Check();
}

EvaluationResult EvaluateTrajectories(const Trajectory& ref, const Trajectory& est,
                                      const EvaluationOptions& options) {
  options.Check();
  const std::filesystem::path est_name = NameForMessages(est, "<estimate>");
  const std::filesystem::path ref_name = NameForMessages(ref, "<reference>");
  if (ref.empty()) throw InputError(ref_name, "empty reference trajectory");
  if (est.empty()) throw InputError(est_name, "empty estimated trajectory");

  EvaluationResult result;
  result.options = options;
  result.ref_poses = ref.size();
  result.est_poses = est.size();
  result.alignment = options.alignment;
  result.pairs = AssociateTimestamps(ref.Timestamps(), est.Timestamps(), options.association);
  if (result.pairs.empty()) {
    const std::int64_t offset_ns = std::llround(options.association.offset_s * 1e9);
    const bool ranges_overlap = est.poses.front().t_ns + offset_ns <= ref.poses.back().t_ns &&
                                ref.poses.front().t_ns <= est.poses.back().t_ns + offset_ns;
    throw InputError(
        est_name,
        fmt::format("no pose within {} s of a pose of {} ({}: ground truth {}, estimate {}{})",
                    options.association.max_diff_s, ref_name.string(),
                    ranges_overlap ? "the time ranges overlap but no stamps are that close"
                                   : "no time overlap",
                    TimeRange(ref), TimeRange(est),
                    options.association.offset_s != 0.0
                        ? fmt::format(", offset {} s", options.association.offset_s)
                        : std::string()));
  }
  const std::size_t needed = MinimumAlignmentPairs(options.alignment);
  if (result.pairs.size() < needed) {
    throw InputError(est_name, fmt::format("only {} pose(s) match {} in time; {} alignment needs "
                                           "at least {}",
                                           result.pairs.size(), ref_name.string(),
                                           AlignmentMethodName(options.alignment), needed));
  }

  std::vector<SE3d> ref_poses;
  std::vector<SE3d> est_poses;
  std::vector<Eigen::Vector3d> ref_positions;
  std::vector<Eigen::Vector3d> est_positions;
  for (const IndexPair& pair : result.pairs) {
    ref_poses.push_back(ref.poses[pair.ref].pose);
    est_poses.push_back(est.poses[pair.est].pose);
    ref_positions.push_back(ref_poses.back().translation());
    est_positions.push_back(est_poses.back().translation());
  }
  result.ref_from_est = AlignPositions(est_positions, ref_positions, options.alignment);

  // The aligned estimate: rotated and translated, positions scaled (rotations have no scale).
  const Sim3d& t = result.ref_from_est;
  for (SE3d& pose : est_poses) {
    pose = SE3d(t.so3() * pose.so3(), t * pose.translation());
  }
  for (std::size_t k = 0; k < est_poses.size(); ++k) {
    result.ate_translation_errors_m.push_back(
        (est_poses[k].translation() - ref_poses[k].translation()).norm());
    result.ate_rotation_errors_deg.push_back(
        (ref_poses[k].so3().Inverse() * est_poses[k].so3()).Angle() * kRadToDeg);
  }
  result.ate_translation_m = ComputeErrorStatistics(result.ate_translation_errors_m);
  result.ate_rotation_deg = ComputeErrorStatistics(result.ate_rotation_errors_deg);
  if (options.compute_rpe) result.rpe = ComputeRpe(ref_poses, est_poses, options.rpe);
  return result;
}

void WriteEvaluationJson(const EvaluationResult& result, JsonWriter& json) {
  json.BeginObject()
      .Member("pairs", result.pairs.size())
      .Member("gt_poses", result.ref_poses)
      .Member("est_poses", result.est_poses)
      .Member("max_diff_s", result.options.association.max_diff_s)
      .Member("alignment", AlignmentMethodName(result.alignment))
      .Member("scale", result.scale());
  json.Key("ate");
  WriteStatistics(result.ate_translation_m, json);
  json.Key("ate_rot_deg");
  WriteStatistics(result.ate_rotation_deg, json);
  json.Key("rpe");
  if (result.rpe) {
    const RpeOptions& rpe = result.options.rpe;
    json.BeginObject()
        .Member("delta", rpe.delta)
        .Member("unit", RpeUnitName(rpe.unit))
        .Member("all_pairs", rpe.all_pairs)
        .Member("pairs", result.rpe->pairs.size());
    json.Key("trans_m");
    WriteStatistics(result.rpe->translation_m, json);
    json.Key("rot_deg");
    WriteStatistics(result.rpe->rotation_deg, json);
    json.EndObject();
  } else {
    json.Null();
  }
  json.EndObject();
}

std::string EvaluationJson(const EvaluationResult& result) {
  JsonWriter json(2);
  WriteEvaluationJson(result, json);
  return json.str();
}

std::string FormatEvaluationTable(const EvaluationResult& result) {
  std::string out = fmt::format(
      "pairs      {} (ground truth {} poses, estimate {} poses, max diff {} s)\n"
      "alignment  {}, scale {:.6f}\n\n",
      result.pairs.size(), result.ref_poses, result.est_poses,
      result.options.association.max_diff_s, AlignmentMethodName(result.alignment), result.scale());
  out += fmt::format("{:<14} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>11}\n", "", "rmse",
                     "mean", "median", "std", "min", "max", "sse");
  out += StatisticsRow("ATE [m]", result.ate_translation_m);
  out += StatisticsRow("ATE rot [deg]", result.ate_rotation_deg);
  if (result.rpe) {
    out += StatisticsRow("RPE [m]", result.rpe->translation_m);
    out += StatisticsRow("RPE rot [deg]", result.rpe->rotation_deg);
    const RpeOptions& rpe = result.options.rpe;
    out += fmt::format("(RPE: delta {} {}, {} pairs, {} pose pairs)\n", rpe.delta,
                       RpeUnitName(rpe.unit), rpe.all_pairs ? "all" : "consecutive",
                       result.rpe->pairs.size());
  }
  return out;
}

}  // namespace pkslam
