#include "evaluation/evaluation_output.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>

#include "core/util/output_file.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;
constexpr double kRadToDeg = 180.0 / M_PI;

// Roll, pitch, yaw (deg) with R = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Vector3d RollPitchYawDeg(const SO3d& rotation) {
  const Eigen::Matrix3d r = rotation.Matrix();
  return Eigen::Vector3d(std::atan2(r(2, 1), r(2, 2)),
                         std::atan2(-r(2, 0), std::hypot(r(0, 0), r(1, 0))),
                         std::atan2(r(1, 0), r(0, 0))) *
         kRadToDeg;
}

double Seconds(std::int64_t t_ns) { return static_cast<double>(t_ns) * 1e-9; }

bool IsGenericStem(const std::string& stem) {
  static constexpr const char* kGeneric[] = {"trajectory",
                                             "trajectory_body",
                                             "trajectory_camera",
                                             "CameraTrajectory",
                                             "FrameTrajectory",
                                             "data",
                                             "stamped_traj_estimate",
                                             "estimate"};
  for (const char* generic : kGeneric) {
    if (stem == generic) return true;
  }
  return stem.rfind("f_", 0) == 0;  // ORB-SLAM3's f_<name>.txt
}

std::string Sanitize(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const bool keep =
        std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
    out += keep ? c : '_';
  }
  return out.empty() ? std::string("estimate") : out;
}

}  // namespace

std::string EstimateLabel(const fs::path& estimate_file) {
  const std::string stem = estimate_file.stem().string();
  if (!IsGenericStem(stem)) return Sanitize(stem);
  const fs::path folder = fs::absolute(estimate_file).parent_path();
  std::string label = folder.filename().string();
  // A bench run folder is named by its seed (CONFIG/seed1): it reads better with its
  // configuration.
  const bool index_only = label.size() > 4 && label.rfind("seed", 0) == 0 &&
                          std::all_of(label.begin() + 4, label.end(), [](char c) {
                            return std::isdigit(static_cast<unsigned char>(c)) != 0;
                          });
  if (index_only && folder.has_parent_path() && !folder.parent_path().filename().empty()) {
    label = folder.parent_path().filename().string() + "_" + label;
  }
  return Sanitize(label);
}

std::vector<std::string> UniqueLabels(const std::vector<fs::path>& estimate_files) {
  std::vector<std::string> labels;
  std::map<std::string, int> seen;
  for (const fs::path& file : estimate_files) {
    std::string label = EstimateLabel(file);
    const int count = ++seen[label];
    if (count > 1) label += fmt::format("_{}", count);
    labels.push_back(label);
  }
  return labels;
}

Trajectory AlignedEstimate(const Trajectory& est, const EvaluationResult& result) {
  Trajectory aligned;
  for (std::size_t k = 0; k < result.pairs.size(); ++k) {
    const std::int64_t t_ns = est.poses[result.pairs[k].est].t_ns;
    if (!aligned.empty() && aligned.poses.back().t_ns >= t_ns) continue;
    aligned.poses.push_back({t_ns, result.aligned_est[k]});
  }
  return aligned;
}

void WriteAlignedEstimate(const fs::path& dir, const std::string& label, const Trajectory& est,
                          const EvaluationResult& result) {
  fs::create_directories(dir);
  WriteTrajectoryTum(AlignedEstimate(est, result), dir / (label + "_aligned.tum"));
}

void WriteErrorFiles(const fs::path& dir, const std::string& label, const Trajectory& est,
                     const EvaluationResult& result) {
  fs::create_directories(dir);
  auto time_of = [&](std::size_t k) { return Seconds(est.poses[result.pairs[k].est].t_ns); };

  OutputFile poses(dir / (label + "_poses.csv"));
  poses.stream() << "t_s,gt_x,gt_y,gt_z,gt_roll_deg,gt_pitch_deg,gt_yaw_deg,est_x,est_y,est_z,"
                    "est_roll_deg,est_pitch_deg,est_yaw_deg,ate_m,ate_rot_deg,distance_m\n";
  double distance_m = 0.0;
  for (std::size_t k = 0; k < result.pairs.size(); ++k) {
    const SE3d& gt = result.matched_ref[k];
    const SE3d& e = result.aligned_est[k];
    if (k > 0) distance_m += (gt.translation() - result.matched_ref[k - 1].translation()).norm();
    const Eigen::Vector3d gt_rpy = RollPitchYawDeg(gt.so3());
    const Eigen::Vector3d est_rpy = RollPitchYawDeg(e.so3());
    poses.stream() << fmt::format(
        "{:.9f},{:.9g},{:.9g},{:.9g},{:.6f},{:.6f},{:.6f},{:.9g},{:.9g},{:.9g},{:.6f},{:.6f},"
        "{:.6f},{:.9g},{:.9g},{:.6f}\n",
        time_of(k), gt.translation().x(), gt.translation().y(), gt.translation().z(), gt_rpy.x(),
        gt_rpy.y(), gt_rpy.z(), e.translation().x(), e.translation().y(), e.translation().z(),
        est_rpy.x(), est_rpy.y(), est_rpy.z(), result.ate_translation_errors_m[k],
        result.ate_rotation_errors_deg[k], distance_m);
  }
  poses.Commit();

  if (result.rpe) {
    OutputFile rpe(dir / (label + "_rpe.csv"));
    rpe.stream() << "t_start_s,t_end_s,trans_m,rot_deg\n";
    for (std::size_t p = 0; p < result.rpe->pairs.size(); ++p) {
      const auto [i, j] = result.rpe->pairs[p];
      rpe.stream() << fmt::format("{:.9f},{:.9f},{:.9g},{:.9g}\n", time_of(i), time_of(j),
                                  result.rpe->translation_errors_m[p],
                                  result.rpe->rotation_errors_deg[p]);
    }
    rpe.Commit();
  }
  WriteSegmentErrorsCsv(dir / (label + "_segments.csv"), est, result);
}

void WriteSegmentErrorsCsv(const fs::path& file, const Trajectory& est,
                           const EvaluationResult& result) {
  auto time_of = [&](std::size_t k) { return Seconds(est.poses[result.pairs[k].est].t_ns); };
  if (result.segments) {
    OutputFile segments(file);
    segments.stream() << "length_m,t_start_s,t_end_s,trans_m,trans_percent,rot_deg,"
                         "rot_deg_per_m,yaw_deg,gravity_deg\n";
    for (const SegmentErrors& s : *result.segments) {
      for (std::size_t p = 0; p < s.pairs.size(); ++p) {
        segments.stream() << fmt::format(
            "{:.2f},{:.9f},{:.9f},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", s.length_m,
            time_of(s.pairs[p].first), time_of(s.pairs[p].second), s.translation_m[p],
            s.translation_percent[p], s.rotation_deg[p], s.rotation_deg_per_m[p], s.yaw_deg[p],
            s.gravity_deg[p]);
      }
    }
    segments.Commit();
  }
}

std::string FormatComparisonTable(const std::vector<std::string>& labels,
                                  const std::vector<EvaluationResult>& results) {
  std::size_t width = 8;
  for (const std::string& label : labels) width = std::max(width, label.size());
  std::string out = fmt::format(
      "{:<{}} {:>6} {:>8} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10} "
      "{:>10}\n",
      "estimate", width, "pairs", "scale", "ATE rmse", "mean", "median", "max", "rot rmse",
      "RPE rmse", "RPE rot");
  for (std::size_t k = 0; k < results.size(); ++k) {
    const EvaluationResult& r = results[k];
    const std::string rpe = r.rpe ? fmt::format("{:>10.6f} {:>10.4f}", r.rpe->translation_m.rmse,
                                                r.rpe->rotation_deg.rmse)
                                  : fmt::format("{:>10} {:>10}", "-", "-");
    out += fmt::format(
        "{:<{}} {:>6} {:>8.4f} {:>10.6f} {:>10.6f} {:>10.6f} {:>10.6f} {:>10.4f} "
        "{}\n",
        labels[k], width, r.pairs.size(), r.scale(), r.ate_translation_m.rmse,
        r.ate_translation_m.mean, r.ate_translation_m.median, r.ate_translation_m.max,
        r.ate_rotation_deg.rmse, rpe);
  }
  out += "(ATE and RPE translation in m, rotations in deg)\n";
  return out;
}

}  // namespace pkslam
