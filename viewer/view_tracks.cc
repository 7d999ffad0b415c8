#include "viewer/view_tracks.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <string_view>

#include "core/util/error.h"
#include "evaluation/evaluate.h"
#include "io/rigid_transform_file.h"

namespace pkslam {

namespace fs = std::filesystem;

AlignedEstimate AlignToGroundTruth(const Trajectory& ground_truth, const Trajectory& estimate,
                                   AlignmentMethod method) {
  EvaluationOptions eval;
  eval.alignment = method;
  eval.compute_rpe = false;
  eval.allow_frame_offset = true;  // the run's own frame pairing (as the bench); for drawing
  const EvaluationResult e = EvaluateTrajectories(ground_truth, estimate, eval);
  AlignedEstimate out;
  out.world_from_map = e.ref_from_est;
  out.ate_rmse_m = e.ate_translation_m.rmse;
  std::vector<double> ate(estimate.poses.size(), -1.0);
  for (std::size_t i = 0; i < e.pairs.size(); ++i)
    ate[e.pairs[i].est] = e.ate_translation_errors_m[i];
  const Sim3d& w = out.world_from_map;
  for (std::size_t i = 0; i < estimate.poses.size(); ++i) {
    const StampedPose& p = estimate.poses[i];
    out.poses.push_back({static_cast<double>(p.t_ns) * 1e-9,
                         SE3d(w.so3() * p.pose.so3(), w * p.pose.translation()), ate[i]});
  }
  return out;
}

std::string RunFolderName(const fs::path& run) {
  fs::path p = fs::absolute(run).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  std::string name = p.filename().string();
  // Bench run folders are named by their seed (CONFIG/seed1): the configuration tells them
  // apart in a legend, the index alone does not.
  auto numbered = [&](std::string_view prefix) {
    return name.size() > prefix.size() && name.rfind(prefix, 0) == 0 &&
           std::all_of(name.begin() + static_cast<std::ptrdiff_t>(prefix.size()), name.end(),
                       [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; });
  };
  const bool index_only = numbered("seed");
  if (index_only && !p.parent_path().filename().empty()) {
    name = p.parent_path().filename().string() + "/" + name;
  }
  return name;
}

std::vector<ViewKeyframe> ReadRunKeyframes(const fs::path& run, const Sim3d& world_from_map) {
  std::vector<ViewKeyframe> out;
  if (!fs::exists(run / "keyframes.txt")) return out;
  for (const StampedPose& p : ReadTrajectory(run / "keyframes.txt").poses) {
    out.push_back({static_cast<double>(p.t_ns) * 1e-9,
                   SE3d(world_from_map.so3() * p.pose.so3(), world_from_map * p.pose.translation()),
                   ""});
  }
  return out;
}

ViewTrack LoadRunTrack(const fs::path& run, const fs::path& ground_truth_file) {
  if (!fs::is_directory(run)) throw InputError(run, "not a run folder");
  const RunAndGroundTruth pair = ReadRunAndGroundTruth(run, ground_truth_file, /*monocular=*/true);
  const bool monocular = !fs::exists(run / "trajectory_body.txt");
  const AlignmentMethod method = monocular ? AlignmentMethod::kSim3 : AlignmentMethod::kSE3;
  AlignedEstimate aligned = AlignToGroundTruth(pair.ground_truth, pair.estimate, method);
  ViewTrack track;
  track.label = RunFolderName(run);
  track.source = "run";
  track.alignment = std::string(AlignmentMethodName(method));
  track.ate_rmse_m = aligned.ate_rmse_m;
  track.estimate = std::move(aligned.poses);
  track.keyframes = ReadRunKeyframes(run, aligned.world_from_map);
  return track;
}

ViewTrack LoadTrajectoryTrack(const ViewTrajectoryFile& file, const Trajectory& ground_truth,
                              bool shown_in_camera, const fs::path& first_run,
                              AlignmentMethod method) {
  if (!fs::is_regular_file(file.file)) throw InputError(file.file, "not found (--trajectory)");
  // Peers (ORB-SLAM3) can repeat a stamp; evo evaluates every such pose, so does the page.
  Trajectory t = ReadTrajectory(file.file, TrajectoryFormat::kAuto, DuplicateTimestamps::kKeepAll);
  const bool in_camera = file.frame == TrajectorySensorFrame::kCamera;
  if (in_camera != shown_in_camera) {
    const fs::path extrinsic = first_run / "body_from_camera.txt";
    if (!fs::exists(extrinsic)) {
      throw InputError(file.file,
                       fmt::format("{} poses, but {} is missing to move them into the {} frame "
                                   "the first run is compared in (--trajectory-frame)",
                                   in_camera ? "camera" : "body", extrinsic.string(),
                                   shown_in_camera ? "camera" : "body"));
    }
    const SE3d body_from_camera = ReadRigidTransform(extrinsic);
    t = ChangeSensorFrame(t, in_camera ? body_from_camera.Inverse() : body_from_camera);
  }
  AlignedEstimate aligned = AlignToGroundTruth(ground_truth, t, method);
  ViewTrack track;
  track.label = file.label.empty() ? file.file.filename().string() : file.label;
  track.source = "trajectory";
  track.alignment = std::string(AlignmentMethodName(method));
  track.ate_rmse_m = aligned.ate_rmse_m;
  track.estimate = std::move(aligned.poses);
  return track;
}

}  // namespace pkslam
