#include "viewer/view_data.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <unordered_map>

#include "core/util/error.h"
#include "io/json_file.h"
#include "io/point_cloud.h"
#include "io/rigid_transform_file.h"
#include "io/text_rows.h"
#include "io/trajectory.h"
#include "viewer/view_tracks.h"

namespace pkslam {

namespace fs = std::filesystem;

TrajectorySensorFrame ParseTrajectorySensorFrame(std::string_view name) {
  if (name == "body") return TrajectorySensorFrame::kBody;
  if (name == "camera") return TrajectorySensorFrame::kCamera;
  throw OptionError(fmt::format("option --trajectory-frame: '{}' (body or camera)", name));
}

void ViewOptions::Check() const {
  PKSLAM_CHECK_OPTION(!run.empty(), "--run", "{}", "a run folder is required");
  PKSLAM_CHECK_OPTION(max_map_points > 0 && max_cloud_points > 0, "point budgets", "{} / {}",
                      max_map_points, max_cloud_points);
  if ((!more_runs.empty() || !trajectories.empty()) && ground_truth.empty() && dataset.empty()) {
    throw OptionError(
        "option --gt or --dataset: needed with several runs or a --trajectory (each is aligned "
        "to the ground truth, so they share one frame)");
  }
  PKSLAM_CHECK_OPTION(trajectory_alignment == AlignmentMethod::kSE3 ||
                          trajectory_alignment == AlignmentMethod::kSim3,
                      "--trajectory-align", "{} (se3 or sim3)",
                      AlignmentMethodName(trajectory_alignment));
}

namespace {

// A CSV with a header line: calls fn(header, row) for each data row.
void ForEachCsvRow(const fs::path& file,
                   const std::function<void(const std::vector<std::string>&, const TextRow&)>& fn) {
  std::vector<std::string> header;
  ForEachDataRow(file, FieldSeparator::kComma, [&](const TextRow& row) {
    if (header.empty()) {
      for (auto f : row.fields) header.emplace_back(f);
      return;
    }
    if (row.fields.size() != header.size()) {
      throw InputError(
          file, row.line,
          fmt::format("{} fields, the header has {}", row.fields.size(), header.size()));
    }
    fn(header, row);
  });
}

std::int64_t Micros(double t_s) { return std::llround(t_s * 1e6); }

// Every k-th point so at most `budget` remain (deterministic).
template <class T>
std::vector<T> Subsample(const std::vector<T>& in, std::size_t budget) {
  if (in.size() <= budget) return in;
  std::vector<T> out;
  const double step = static_cast<double>(in.size()) / static_cast<double>(budget);
  for (std::size_t i = 0; i < budget; ++i) {
    out.push_back(in[static_cast<std::size_t>(static_cast<double>(i) * step)]);
  }
  return out;
}

// stats.json's warnings (none when the file is absent: a run cut short by a kill).
std::vector<std::string> RunWarnings(const fs::path& stats) {
  std::vector<std::string> out;
  if (!fs::exists(stats)) return out;
  const YAML::Node root = ReadJsonFile(stats);
  for (const char* section : {"input", "estimate", "calibration"}) {
    const YAML::Node node = root[section];
    if (!node || !node.IsMap() || !node["warnings"] || !node["warnings"].IsSequence()) continue;
    for (const YAML::Node& w : node["warnings"]) {
      out.push_back(std::string(section) + ": " + w.as<std::string>(""));
    }
  }
  return out;
}

// stats.json's online calibration: applied adjustments and the file's values.
void ReadCalibration(const fs::path& stats, ViewData* data) {
  if (!fs::exists(stats)) return;
  const YAML::Node c = ReadJsonFile(stats)["calibration"];
  if (!c || !c.IsMap() || c["mode"].as<std::string>("") != "online") return;
  for (const YAML::Node& p : c["parameters"]) {
    data->calibration_file[p["name"].as<std::string>("")] = p["file"].as<double>(0.0);
  }
  for (const YAML::Node& h : c["history"]) {
    if (!h["applied"].as<bool>(false)) continue;
    ViewCalibrationStep step;
    step.t_s = h["t_s"].as<double>(0.0);
    for (const auto& kv : h["estimate"]) {
      step.estimate[kv.first.as<std::string>()] = kv.second.as<double>(0.0);
    }
    data->calibration.push_back(std::move(step));
  }
}

fs::path ResolveGroundTruth(const ViewOptions& options) {
  if (!options.ground_truth.empty() || options.dataset.empty()) return options.ground_truth;
  const auto found = FindDatasetGroundTruth(options.dataset);
  if (!found) {
    throw InputError(options.dataset,
                     "no ground truth (mav0/state_groundtruth_estimate0/"
                     "data.csv or groundtruth.txt)");
  }
  return *found;
}

// The run's trajectory as displayed: aligned to the ground truth when there is one.
struct ShownEstimate {
  Sim3d world_from_map;  // the displayed world from the run's map world
  Trajectory ground_truth;
  bool in_camera = true;
};

ShownEstimate LoadEstimate(const fs::path& run, const fs::path& gt, ViewData* data) {
  ShownEstimate shown;
  if (gt.empty()) {
    data->alignment = "none";
    const Trajectory t = ReadTrajectory(run / "trajectory.txt");
    for (const StampedPose& p : t.poses) {
      data->estimate.push_back({static_cast<double>(p.t_ns) * 1e-9, p.pose, -1.0});
    }
    return shown;
  }
  // Camera poses throughout (the ground truth moved into the camera when the run has the
  // extrinsic): the keyframe frustums are cameras, and drawn along a body path they sat a
  // lever arm (6.7 cm on EuRoC) off it.
  RunAndGroundTruth pair = ReadRunAndGroundTruth(run, gt, /*monocular=*/true);
  const bool monocular = !fs::exists(run / "trajectory_body.txt");
  const AlignmentMethod method = monocular ? AlignmentMethod::kSim3 : AlignmentMethod::kSE3;
  AlignedEstimate aligned = AlignToGroundTruth(pair.ground_truth, pair.estimate, method);
  shown.world_from_map = aligned.world_from_map;
  data->alignment = std::string(AlignmentMethodName(method));
  data->ate_rmse_m = aligned.ate_rmse_m;
  data->estimate = std::move(aligned.poses);
  // The ground truth over the estimate's time span, at most ~5000 vertices.
  const auto& g = pair.ground_truth.poses;
  const std::int64_t t0 = pair.estimate.poses.empty() ? 0 : pair.estimate.poses.front().t_ns;
  const std::int64_t t1 = pair.estimate.poses.empty() ? 0 : pair.estimate.poses.back().t_ns;
  std::vector<Eigen::Vector3d> path;
  for (const StampedPose& p : g) {
    if (p.t_ns >= t0 - 1'000'000'000 && p.t_ns <= t1 + 1'000'000'000) {
      path.push_back(p.pose.translation());
    }
  }
  data->ground_truth = Subsample(path, 5000);
  shown.in_camera = pair.estimate_file.filename() == "trajectory.txt";
  shown.ground_truth = std::move(pair.ground_truth);
  return shown;
}

// keyframe_trace.csv: each keyframe's rule, and each traced frame's reason and quantities.
struct DecisionTrace {
  std::unordered_map<std::int64_t, std::string> reasons;  // keyframes, by time (us)
  std::unordered_map<std::int64_t, std::size_t> row_of_frame;
  std::vector<std::pair<std::string, std::map<std::string, double>>> rows;
};

DecisionTrace ReadDecisionTrace(const fs::path& run, ViewData* data) {
  DecisionTrace out;
  const fs::path trace = run / "keyframe_trace.csv";
  if (!fs::exists(trace)) return out;
  ForEachCsvRow(trace, [&](const std::vector<std::string>& header, const TextRow& row) {
    double t = 0;
    std::int64_t frame = -1;
    bool insert = false;
    std::string reason;
    std::map<std::string, double> values;
    for (std::size_t i = 0; i < header.size(); ++i) {
      const std::string_view f = row.fields[i];
      if (header[i] == "time") {
        t = DoubleField(f, trace, row.line, "time");
      } else if (header[i] == "frame") {
        frame = Int64Field(f, trace, row.line, "frame");
      } else if (header[i] == "decision") {
        insert = f == "1";
      } else if (header[i] == "reason") {
        reason = std::string(f);
      } else if (header[i] == "selector") {
        if (data->selector.empty()) data->selector = std::string(f);
      } else if (!f.empty()) {
        if (const auto v = ParseDouble(f)) values[header[i]] = *v;
      }
    }
    if (insert) out.reasons[Micros(t)] = reason;
    out.row_of_frame[frame] = out.rows.size();
    out.rows.emplace_back(reason, std::move(values));
  });
  return out;
}

// A PLY's points in the displayed world, at most `budget` of them (and their colours into
// data->cloud_colours when asked).
std::vector<Eigen::Vector3f> LoadPoints(const fs::path& file, std::size_t budget, bool colours,
                                        const Sim3d& world_from_map, ViewData* data) {
  const PointCloud cloud = ReadPly(file);
  std::vector<std::size_t> index(cloud.size());
  for (std::size_t i = 0; i < index.size(); ++i) index[i] = i;
  index = Subsample(index, budget);
  std::vector<Eigen::Vector3f> points;
  for (std::size_t i : index) {
    points.push_back((world_from_map * cloud.points[i].cast<double>()).cast<float>());
    if (colours && cloud.has_colour()) data->cloud_colours.push_back(cloud.colours[i]);
  }
  return points;
}

// Timeline: frames.csv, joined with the trace by frame id.
void ReadTimeline(const fs::path& run, const DecisionTrace& trace, ViewData* data) {
  const fs::path frames = run / "frames.csv";
  if (!fs::exists(frames)) return;
  ForEachCsvRow(frames, [&](const std::vector<std::string>& header, const TextRow& row) {
    ViewTimelineRow r;
    for (std::size_t i = 0; i < header.size(); ++i) {
      const std::string_view f = row.fields[i];
      if (header[i] == "time") r.t_s = DoubleField(f, frames, row.line, "time");
      if (header[i] == "frame") r.frame = Int64Field(f, frames, row.line, "frame");
      if (header[i] == "state") r.state = std::string(f);
      if (header[i] == "tracked_points") {
        r.tracked_points = static_cast<int>(Int64Field(f, frames, row.line, "tracked_points"));
      }
      if (header[i] == "keyframe") r.keyframe = f == "1";
    }
    if (const auto it = trace.row_of_frame.find(r.frame); it != trace.row_of_frame.end()) {
      r.decision_reason = trace.rows[it->second].first;
      r.quantities = trace.rows[it->second].second;
    }
    data->timeline.push_back(std::move(r));
  });
}

// Further runs and bare trajectories, aligned to the same ground truth (Check: there is one).
// Labels name the legend's rows: two runs in folders of the same name get "name (2)".
void AddTracks(const ViewOptions& options, const fs::path& gt, const ShownEstimate& shown,
               ViewData* data) {
  for (const fs::path& r : options.more_runs) data->tracks.push_back(LoadRunTrack(r, gt));
  for (const ViewTrajectoryFile& f : options.trajectories) {
    data->tracks.push_back(LoadTrajectoryTrack(f, shown.ground_truth, shown.in_camera, options.run,
                                               options.trajectory_alignment));
  }
  std::vector<std::string> labels{data->title};
  for (ViewTrack& t : data->tracks) {
    const std::string base = t.label;
    for (int n = 2; std::find(labels.begin(), labels.end(), t.label) != labels.end(); ++n) {
      t.label = fmt::format("{} ({})", base, n);
    }
    labels.push_back(t.label);
  }
}

}  // namespace

ViewData LoadViewData(const ViewOptions& options) {
  options.Check();
  const fs::path& run = options.run;
  if (!fs::is_directory(run)) throw InputError(run, "not a run folder");
  ViewData data;
  data.title = RunFolderName(run);
  const fs::path gt = ResolveGroundTruth(options);
  const ShownEstimate shown = LoadEstimate(run, gt, &data);

  // Keyframes and the rule that created each.
  const DecisionTrace trace = ReadDecisionTrace(run, &data);
  data.keyframes = ReadRunKeyframes(run, shown.world_from_map);
  for (ViewKeyframe& k : data.keyframes) {
    if (const auto it = trace.reasons.find(Micros(k.t_s)); it != trace.reasons.end()) {
      k.reason = it->second;
    }
  }

  // Map points and the dense cloud, in the displayed world.
  if (fs::exists(run / "map_points.ply")) {
    data.map_points = LoadPoints(run / "map_points.ply", options.max_map_points, false,
                                 shown.world_from_map, &data);
  }
  const fs::path cloud = options.cloud.empty() ? run / "dense.ply" : options.cloud;
  if (!options.cloud.empty() && !fs::exists(cloud)) throw InputError(cloud, "not found (--cloud)");
  if (fs::exists(cloud)) {
    data.cloud = LoadPoints(cloud, options.max_cloud_points, true, shown.world_from_map, &data);
  }

  ReadTimeline(run, trace, &data);
  data.warnings = RunWarnings(run / "stats.json");
  ReadCalibration(run / "stats.json", &data);
  AddTracks(options, gt, shown, &data);
  return data;
}

}  // namespace pkslam
