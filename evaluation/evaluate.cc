#include "evaluation/evaluate.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "core/util/error.h"
#include "core/util/quantile.h"

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

// Matched poses must be numbers; for a Sim(3) alignment each side must also move: with all
// positions in one place the scale is free (it shrinks the estimate onto the truth, or grows it
// anywhere). A rigid alignment of a static side still measures the other side's spread.
void CheckPosesUsable(const std::vector<SE3d>& poses, const std::vector<IndexPair>& pairs,
                      bool estimate, bool need_spread, const std::filesystem::path& name) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const SE3d& pose = poses[k];
    if (!pose.translation().allFinite() || !pose.so3().Matrix().allFinite()) {
      throw InputError(name, fmt::format("pose {} of the file (matched pair {}) is not finite",
                                         (estimate ? pairs[k].est : pairs[k].ref) + 1, k + 1));
    }
    mean += pose.translation();
  }
  if (!need_spread) return;
  mean /= static_cast<double>(poses.size());
  double spread_sq = 0;
  for (const SE3d& pose : poses) spread_sq += (pose.translation() - mean).squaredNorm();
  const double spread_m = std::sqrt(spread_sq / static_cast<double>(poses.size()));
  if (spread_m < 1e-6) {
    throw InputError(name,
                     fmt::format("the {} matched {} poses all sit at one place (RMS spread "
                                 "{:.2g} m): a Sim(3) alignment has no scale to find",
                                 poses.size(), estimate ? "estimate" : "reference", spread_m));
  }
}

// After alignment the orientations of estimate and reference should agree up to drift. A large
// rotation between them that is nearly the same at every pose means the two describe different
// frames of the rig (ORB-SLAM3 and pkslam write camera poses; EuRoC's ground truth is the body,
// whose camera sits at about 90 degrees): the numbers would measure the calibration, not the run.
void CheckSameBodyFrame(const std::vector<SE3d>& ref, const std::vector<SE3d>& est,
                        const std::filesystem::path& est_name) {
  // Along a nearly straight path the alignment cannot fix the rotation about the path from
  // positions alone, and an offset about it is the alignment's, not the files'.
  Eigen::Vector3d mean_position = Eigen::Vector3d::Zero();
  for (const SE3d& pose : ref) mean_position += pose.translation();
  mean_position /= static_cast<double>(ref.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const SE3d& pose : ref) {
    const Eigen::Vector3d d = pose.translation() - mean_position;
    scatter += d * d.transpose();
  }
  const Eigen::Vector3d spread = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter)
                                     .eigenvalues()
                                     .cwiseMax(0.0)
                                     .cwiseSqrt();  // ascending
  if (spread(2) < 1e-6 || spread(1) < 0.1 * spread(2)) return;
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  std::vector<SO3d> offsets;
  for (std::size_t k = 0; k < ref.size(); ++k) {
    offsets.push_back(ref[k].so3().Inverse() * est[k].so3());
    sum += offsets.back().Matrix();
  }
  const SO3d mean = SO3d::FitToMatrix(sum);  // chordal mean of the offsets
  const double offset_deg = mean.Angle() * kRadToDeg;
  if (offset_deg <= 5.0) return;
  std::vector<double> residual_deg;
  for (const SO3d& r : offsets) residual_deg.push_back((mean.Inverse() * r).Angle() * kRadToDeg);
  const double p90_deg = *Quantile(std::move(residual_deg), 0.9);
  if (p90_deg > offset_deg / 3.0) return;  // not constant: drift or a failed run, measured as is
  throw InputError(
      est_name,
      fmt::format("its orientation differs from the ground truth's by a near-constant {:.1f} deg "
                  "(90% of poses within {:.1f} deg of it): the two describe different frames, "
                  "e.g. camera poses against body (IMU) ground truth. Evaluate the run's "
                  "trajectory_body.txt, or pass --body-from-camera RUN/body_from_camera.txt "
                  "(Python: body_from_camera=); --allow-frame-offset measures anyway",
                  offset_deg, p90_deg));
}

}  // namespace

std::string FormatSegmentTable(const std::vector<SegmentErrors>& segments) {
  std::string out = fmt::format(
      "\nrelative error over segment lengths (rpg_trajectory_evaluation):\n"
      "{:>10} {:>6} {:>12} {:>12} {:>12} {:>12}\n",
      "length [m]", "pairs", "trans median", "trans rmse", "trans [%]", "rot [deg]");
  for (const SegmentErrors& s : segments) {
    if (s.empty()) {
      out += fmt::format("{:>10.2f} {:>6} (longer than the trajectory allows)\n", s.length_m, 0);
      continue;
    }
    out += fmt::format("{:>10.2f} {:>6} {:>12.6f} {:>12.6f} {:>12.4f} {:>12.4f}\n", s.length_m,
                       s.pairs.size(), s.translation_m_stats.median, s.translation_m_stats.rmse,
                       s.translation_percent_stats.median, s.rotation_deg_stats.median);
  }
  out += "(translation and rotation medians over the segments; [%] of the segment length)\n";
  return out;
}

std::string FormatKittiTable(const KittiErrors& kitti) {
  if (kitti.empty()) {
    return "\nKITTI odometry metric: no segment (the path is shorter than the shortest length)\n";
  }
  std::string out = fmt::format(
      "\nKITTI odometry metric (devkit): translation {:.4f} %, rotation {:.4f} deg/100 m over {} "
      "segments\n{:>10} {:>9} {:>12} {:>16}\n",
      kitti.translation_percent, kitti.rotation_deg_per_100m, kitti.segments.size(), "length [m]",
      "segments", "trans [%]", "rot [deg/100 m]");
  for (const auto& p : kitti.per_length) {
    out += fmt::format("{:>10.0f} {:>9} {:>12.4f} {:>16.4f}\n", p.length_m, p.segments,
                       p.translation_percent, p.rotation_deg_per_100m);
  }
  return out;
}

void EvaluationOptions::Check() const {
  association.Check();
  if (compute_rpe) rpe.Check();
  if (compute_segments) segments.Check();
  if (compute_kitti) kitti.Check();
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
  const bool sim3 = options.alignment == AlignmentMethod::kSim3;
  CheckPosesUsable(ref_poses, result.pairs, false, sim3, ref_name);
  CheckPosesUsable(est_poses, result.pairs, true, sim3, est_name);
  result.ref_from_est = AlignPositions(est_positions, ref_positions, options.alignment);

  // The aligned estimate: rotated and translated, positions scaled (rotations have no scale).
  const Sim3d& t = result.ref_from_est;
  for (SE3d& pose : est_poses) {
    pose = SE3d(t.so3() * pose.so3(), t * pose.translation());
  }
  if (!options.allow_frame_offset) CheckSameBodyFrame(ref_poses, est_poses, est_name);
  for (std::size_t k = 0; k < est_poses.size(); ++k) {
    result.ate_translation_errors_m.push_back(
        (est_poses[k].translation() - ref_poses[k].translation()).norm());
    result.ate_rotation_errors_deg.push_back(
        (ref_poses[k].so3().Inverse() * est_poses[k].so3()).Angle() * kRadToDeg);
  }
  result.ate_translation_m = ComputeErrorStatistics(result.ate_translation_errors_m);
  result.ate_rotation_deg = ComputeErrorStatistics(result.ate_rotation_errors_deg);
  if (options.compute_rpe) result.rpe = ComputeRpe(ref_poses, est_poses, options.rpe);
  if (options.compute_segments) {
    SegmentErrorOptions segments = options.segments;
    if (segments.reference_path_m == 0.0) segments.reference_path_m = PathLengthMeters(ref);
    result.segments = ComputeSegmentErrors(ref_poses, est_poses, segments);
  }
  if (options.compute_kitti) result.kitti = ComputeKittiErrors(ref_poses, est_poses, options.kitti);
  result.matched_ref = std::move(ref_poses);
  result.aligned_est = std::move(est_poses);
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
  json.Key("segments");
  if (result.segments) {
    json.BeginArray();
    for (const SegmentErrors& segment : *result.segments) {
      json.BeginObject().Member("length_m", segment.length_m).Member("pairs", segment.pairs.size());
      const std::pair<const char*, const ErrorStatistics*> stats[] = {
          {"trans_m", &segment.translation_m_stats},
          {"trans_percent", &segment.translation_percent_stats},
          {"rot_deg", &segment.rotation_deg_stats}};
      for (const auto& [key, s] : stats) {
        json.Key(key);
        if (segment.empty()) {
          json.Null();
        } else {
          WriteStatistics(*s, json);
        }
      }
      json.EndObject();
    }
    json.EndArray();
  } else {
    json.Null();
  }
  json.Key("kitti");
  if (result.kitti) {
    json.BeginObject()
        .Member("segments", result.kitti->segments.size())
        .Member("trans_percent", result.kitti->translation_percent)
        .Member("rot_deg_per_100m", result.kitti->rotation_deg_per_100m);
    json.Key("per_length").BeginArray();
    for (const auto& p : result.kitti->per_length) {
      json.BeginObject()
          .Member("length_m", p.length_m)
          .Member("segments", p.segments)
          .Member("trans_percent", p.translation_percent)
          .Member("rot_deg_per_100m", p.rotation_deg_per_100m)
          .EndObject();
    }
    json.EndArray().EndObject();
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
  if (result.segments) out += FormatSegmentTable(*result.segments);
  if (result.kitti) out += FormatKittiTable(*result.kitti);
  return out;
}

}  // namespace pkslam
