#include "tracks/reconstruction_output.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/util/error.h"
#include "core/util/json_writer.h"
#include "core/util/output_file.h"
#include "evaluation/evaluate.h"
#include "io/point_cloud.h"
#include "io/text_rows.h"

namespace pkslam {

namespace fs = std::filesystem;

std::optional<TracksTruth> ReadTracksTruth(const fs::path& dir) {
  const fs::path trajectory = dir / "truth_trajectory.txt";
  if (!fs::exists(trajectory)) return std::nullopt;
  TracksTruth truth;
  truth.trajectory = ReadTrajectory(trajectory, TrajectoryFormat::kTum);
  const fs::path points = dir / "truth_points.txt";
  if (fs::exists(points)) {
    for (const auto& [id, p] : ReadTrackPoints(points)) truth.points.emplace(id, p);
  }
  return truth;
}

Trajectory TracksTrajectory(const TracksReconstruction& r, const TrackIndex& index,
                            bool keyframes_only) {
  Trajectory t;
  for (std::size_t k = 0; k < r.frames.size(); ++k) {
    const TracksFrameResult& f = r.frames[k];
    if (!f.tracked || (keyframes_only && !f.keyframe)) continue;
    t.poses.push_back({std::llround(index.times_s[k] * 1e9), f.camera_from_world.Inverse()});
  }
  return t;
}

TracksAccuracy EvaluateTracksReconstruction(const TracksReconstruction& r, const TrackIndex& index,
                                            const TracksTruth& truth) {
  const Trajectory estimate = TracksTrajectory(r, index, false);
  EvaluationOptions options;
  options.alignment = AlignmentMethod::kSim3;
  options.compute_rpe = false;
  const EvaluationResult e = EvaluateTrajectories(truth.trajectory, estimate, options);
  TracksAccuracy a;
  a.pairs = e.pairs.size();
  a.scale = e.scale();
  a.ate_m = e.ate_translation_m;
  a.aligned = estimate;
  for (StampedPose& p : a.aligned.poses) {
    const Sim3d& s = e.ref_from_est;
    const Eigen::Vector3d position = s * p.pose.translation();
    p.pose = SE3d(s.so3() * p.pose.so3(), position);
    a.aligned_positions.push_back(position);
  }
  // The map is aligned on its own points (Umeyama, Sim(3)): a position-only alignment of the
  // trajectory leaves the rotation about a straight path (the thesis's line) undetermined.
  std::vector<Eigen::Vector3d> estimated, reference;
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    if (!r.points[i]) continue;
    const auto it = truth.points.find(index.track_ids[i]);
    if (it == truth.points.end()) continue;
    estimated.push_back(*r.points[i]);
    reference.push_back(it->second);
  }
  if (estimated.size() >= 3) {
    const Sim3d map_alignment = UmeyamaAlignment(estimated, reference, true);
    std::vector<double> errors;
    for (std::size_t i = 0; i < estimated.size(); ++i) {
      errors.push_back((map_alignment * estimated[i] - reference[i]).norm());
    }
    a.map_error = ComputeErrorStatistics(errors);
  }
  // Scale of the scene: the truth points' median depth in the truth cameras that pair.
  std::vector<double> depths;
  for (const IndexPair& pair : e.pairs) {
    const SE3d camera_from_world = truth.trajectory.poses[pair.ref].pose.Inverse();
    for (const auto& [id, p] : truth.points) {
      const double z = (camera_from_world * p).z();
      if (z > 0) depths.push_back(z);
    }
    if (depths.size() > 200000) break;
  }
  if (!depths.empty()) {
    std::nth_element(depths.begin(), depths.begin() + static_cast<long>(depths.size() / 2),
                     depths.end());
    a.median_truth_depth = depths[depths.size() / 2];
  }
  return a;
}

namespace {

void WriteStatistics(JsonWriter& json, std::string_view key, const ErrorStatistics& s) {
  json.Key(key).BeginObject();
  json.Member("count", static_cast<std::uint64_t>(s.count));
  json.Member("rmse", s.rmse).Member("mean", s.mean).Member("median", s.median);
  json.Member("std", s.std).Member("max", s.max);
  json.EndObject();
}

double Mean(const std::vector<double>& v) {
  return v.empty() ? std::nan("") : std::accumulate(v.begin(), v.end(), 0.0) / v.size();
}

double Median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

void WriteTracksReconstruction(const fs::path& dir, const TrackSet& tracks, const TrackIndex& index,
                               const TracksReconstruction& r,
                               const std::optional<TracksAccuracy>& accuracy,
                               const TracksOutputOptions& output) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw OutputError(dir, "cannot create: " + ec.message());
  WriteTrajectoryTum(TracksTrajectory(r, index, false), dir / "trajectory.txt");
  WriteTrajectoryTum(TracksTrajectory(r, index, true), dir / "keyframes.txt");
  if (accuracy) WriteTrajectoryTum(accuracy->aligned, dir / "trajectory_aligned.txt");

  PointCloud cloud;
  for (const auto& p : r.points) {
    if (p) cloud.points.push_back(p->cast<float>());
  }
  WritePly(cloud, dir / "map.ply", PlyColour::kNone, "pkslam tracks reconstruct: map points");

  std::string frames_csv =
      "frame,time_s,tracked,keyframe,reason,observations,map_matches,inliers,mean_error_px,"
      "median_error_px\n";
  std::string errors_csv = "frame,track,error_px\n";
  std::vector<double> frame_means(r.frames.size(), std::nan(""));
  std::vector<double> all_errors;
  for (std::size_t k = 0; k < r.frames.size(); ++k) {
    const TracksFrameResult& f = r.frames[k];
    const std::vector<double> errors =
        FrameReprojectionErrors(r, index, tracks.camera, static_cast<int>(k));
    frame_means[k] = Mean(errors);
    all_errors.insert(all_errors.end(), errors.begin(), errors.end());
    frames_csv +=
        fmt::format("{},{:.9f},{},{},{},{},{},{},{:.6g},{:.6g}\n", k, index.times_s[k],
                    f.tracked ? 1 : 0, f.keyframe ? 1 : 0, f.keyframe_reason, f.observations,
                    f.map_matches, f.inliers, frame_means[k], Median(errors));
    std::size_t e = 0;
    if (!f.tracked) continue;
    for (const IndexedObservation& o : index.frames[k]) {
      const auto& p = r.points[static_cast<std::size_t>(o.track)];
      if (!p || (f.camera_from_world * *p).z() <= 0) continue;
      errors_csv += fmt::format("{},{},{:.6g}\n", k,
                                index.track_ids[static_cast<std::size_t>(o.track)], errors[e++]);
    }
  }
  WriteFileAtomically(dir / "frames.csv", frames_csv);
  WriteFileAtomically(dir / "reprojection_errors.csv", errors_csv);

  JsonWriter json;
  json.BeginObject();
  json.Member("frames", static_cast<int>(r.frames.size()));
  json.Member("tracks", index.num_tracks());
  json.Member("observations", static_cast<std::uint64_t>(tracks.observations.size()));
  int tracked = 0;
  for (const auto& f : r.frames) tracked += f.tracked ? 1 : 0;
  json.Member("tracked_frames", tracked);
  json.Member("lost_frames", static_cast<int>(r.frames.size()) - tracked);
  int points = 0;
  for (const auto& p : r.points) points += p ? 1 : 0;
  json.Member("map_points", points);
  json.Member("keyframes", r.num_keyframes);
  json.Key("keyframe_reasons").BeginObject();
  for (const auto& [reason, count] : r.keyframe_reasons) json.Member(reason, count);
  json.EndObject();
  if (output.options) {
    const TracksReconstructionOptions& o = *output.options;
    json.Key("options").BeginObject();
    json.Member("keyframe_rule", TracksKeyframeRuleName(o.keyframe_rule));
    json.Member("init", TracksInitModeName(o.init_mode));
    json.Member("init_min_parallax_deg", o.init_min_parallax_deg);
    json.Member("sigma_px", o.two_view.sigma);
    json.Member("local_window", o.local_window);
    json.Member("global_ba", o.global_ba);
    json.Member("refine_frames", o.refine_frames);
    json.Member("seed", static_cast<std::uint64_t>(o.seed));
    json.EndObject();
  }
  json.Key("init").BeginObject();
  json.Member("first", r.init_first).Member("second", r.init_second);
  json.Member("common_tracks", static_cast<int>(r.init.tracks.size()));
  json.Member("f_inliers", r.init.num_inliers);
  json.Member("triangulated", r.init.num_triangulated);
  json.Member("median_parallax_deg", r.init.median_parallax_deg);
  json.Member("candidate", r.init.best_candidate);
  json.Key("candidate_good").BeginArray();
  for (int g : r.init.candidate_good) json.Value(g);
  json.EndArray();
  json.Member("pairs_refused", static_cast<int>(r.init_refused.size()));
  json.EndObject();
  json.Key("seconds").BeginObject();
  json.Member("init", r.seconds_init).Member("tracking", r.seconds_tracking);
  json.Member("mapping", r.seconds_mapping).Member("total", r.seconds_total);
  json.EndObject();
  json.Member("local_ba_runs", r.local_ba_runs);
  if (!all_errors.empty())
    WriteStatistics(json, "reprojection_px", ComputeErrorStatistics(all_errors));
  json.Key("mean_reprojection_px_per_frame").BeginArray();
  for (double m : frame_means) {
    if (std::isfinite(m)) {
      json.Value(m);
    } else {
      json.Null();
    }
  }
  json.EndArray();
  json.Key("histogram_frames").BeginArray();
  for (int f : output.histogram_frames) json.Value(f);
  json.EndArray();
  if (accuracy) {
    json.Key("accuracy").BeginObject();
    json.Member("pairs", static_cast<std::uint64_t>(accuracy->pairs));
    json.Member("sim3_scale", accuracy->scale);
    WriteStatistics(json, "ate_sim3", accuracy->ate_m);
    if (accuracy->map_error.count > 0) {
      WriteStatistics(json, "map_error", accuracy->map_error);
      json.Member("median_truth_depth", accuracy->median_truth_depth);
    } else {
      json.Key("map_error").Null();
    }
    json.EndObject();
  } else {
    json.Key("accuracy").Null();
  }
  json.EndObject();
  WriteFileAtomically(dir / "stats.json", json.str());
}

}  // namespace pkslam
