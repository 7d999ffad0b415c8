// What `pkslam view` shows of a run, gathered from its output folder (issue 25): the estimated
// trajectory (aligned to ground truth when given, each pose with its ATE), the ground truth,
// the keyframes with the rule that created each (keyframe_trace.csv, from --trace), the map
// points, an optional dense cloud or mesh vertices (subsampled), and the per-frame timeline
// (frames.csv: tracking state and tracked points; keyframe_trace.csv: decision, reason and
// every selector quantity such as PKS's M, D, Th and ECOG). Beside the run, further runs and
// bare trajectory files (issue 41), each aligned to the same ground truth (view_tracks.h).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/geometry/se3.h"
#include "evaluation/alignment.h"

namespace pkslam {

// The sensor a bare trajectory file describes (ORB-SLAM3 writes the IMU body for inertial
// runs, the camera otherwise).
enum class TrajectorySensorFrame { kBody, kCamera };

// "body" or "camera"; throws OptionError otherwise.
TrajectorySensorFrame ParseTrajectorySensorFrame(std::string_view name);

// A bare trajectory shown beside the run: another system's estimate, such as ORB-SLAM3's
// f_*.txt (TUM, EuRoC or ORB-SLAM3 format, detected by io/trajectory.h).
struct ViewTrajectoryFile {
  std::filesystem::path file;
  std::string label;  // empty: the file's name
  TrajectorySensorFrame frame = TrajectorySensorFrame::kBody;
};

struct ViewOptions {
  std::filesystem::path run;
  std::filesystem::path ground_truth;  // empty: none (or from `dataset`)
  std::filesystem::path dataset;       // empty: none; its ground truth when `ground_truth` empty
  std::filesystem::path cloud;         // empty: RUN/dense.ply when present
  std::size_t max_map_points = 200000;
  std::size_t max_cloud_points = 300000;
  // Shown beside `run`, aligned to the same ground truth (which they require): further runs
  // (trajectory and keyframes) and bare trajectory files.
  std::vector<std::filesystem::path> more_runs;
  std::vector<ViewTrajectoryFile> trajectories;
  AlignmentMethod trajectory_alignment = AlignmentMethod::kSE3;  // of the bare files: se3|sim3

  void Check() const;
};

struct ViewPose {
  double t_s = 0;
  SE3d world_from_camera;  // in the displayed world (ground truth's after alignment)
  double ate_m = -1;       // translation error after alignment (-1: no ground truth)
};

struct ViewKeyframe {
  double t_s = 0;
  SE3d world_from_camera;
  std::string reason;  // rule that created it ("" when the run had no --trace)
};

struct ViewTimelineRow {
  double t_s = 0;
  std::int64_t frame = 0;
  std::string state;
  int tracked_points = 0;
  bool keyframe = false;
  std::string decision_reason;               // from keyframe_trace.csv ("" when absent)
  std::map<std::string, double> quantities;  // selector trace values of the frame
};

// One applied online-calibration adjustment (stats.json calibration.history): when, and the
// estimate it ended with (parameter name -> value, docs/calibration.md).
struct ViewCalibrationStep {
  double t_s = 0;
  std::map<std::string, double> estimate;
};

// A further run or bare trajectory, aligned to the run's ground truth as the run is.
struct ViewTrack {
  std::string label;
  std::string source;     // "run" or "trajectory"
  std::string alignment;  // "se3" or "sim3"
  double ate_rmse_m = -1;
  std::vector<ViewPose> estimate;
  std::vector<ViewKeyframe> keyframes;  // a run's (reason not read); none for a bare file
};

struct ViewData {
  std::string title;
  std::string selector;   // the keyframe selector of keyframe_trace.csv ("" without --trace)
  std::string alignment;  // "se3", "sim3" or "none"
  double ate_rmse_m = -1;
  std::vector<ViewPose> estimate;
  std::vector<Eigen::Vector3d> ground_truth;
  std::vector<ViewKeyframe> keyframes;
  std::vector<Eigen::Vector3f> map_points;
  std::vector<Eigen::Vector3f> cloud;  // dense cloud (or mesh vertices), subsampled
  std::vector<std::array<std::uint8_t, 3>> cloud_colours;  // empty or one per cloud point
  std::vector<ViewTimelineRow> timeline;
  // The run's own warnings from stats.json: "input: ..." (degraded input) and "estimate: ..."
  // (suspect estimate, system/estimate_health.h); the page shows them above everything else.
  std::vector<std::string> warnings;
  // Online calibration: the applied adjustments and the file's values (empty for --calibrate
  // off or older runs).
  std::vector<ViewCalibrationStep> calibration;
  std::map<std::string, double> calibration_file;
  // Further runs and bare trajectories (ViewOptions::more_runs, trajectories), in that order.
  std::vector<ViewTrack> tracks;
};

// Reads the run and the tracks beside it (InputError naming the missing or malformed file,
// OptionError for tracks without ground truth).
ViewData LoadViewData(const ViewOptions& options);

// The data as one JSON object (the page's PKSLAM_DATA).
std::string ViewDataJson(const ViewData& data);

}  // namespace pkslam
