#include "system/run_outputs.h"

#include <algorithm>
#include <fstream>
#include <numeric>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "core/util/cpu_time.h"
#include "core/util/error.h"
#include "core/util/json_writer.h"
#include "core/util/log.h"
#include "core/util/output_file.h"
#include "core/util/quantile.h"
#include "io/rigid_transform_file.h"
#include "io/track_file.h"
#include "map_model/map_editor.h"
#include "system/estimate_health.h"
#include "system/inertial_outputs.h"
#include "system/sparse_model_builder.h"

namespace pkslam {
namespace {

// 0 for no values (stats.json's convention).
double Median(std::vector<double> v) { return Quantile(std::move(v), 0.5).value_or(0.0); }

void WriteArray(JsonWriter* json, std::string_view key, const std::vector<double>& values) {
  json->Key(key).BeginArray();
  for (double v : values) json->Value(std::round(v * 1000.0) / 1000.0);
  json->EndArray();
}

void WriteStrings(JsonWriter* json, std::string_view key, const std::vector<std::string>& values) {
  json->Key(key).BeginArray();
  for (const std::string& v : values) json->Value(v);
  json->EndArray();
}

void WriteTrace(const Tracker& tracker, const std::filesystem::path& file) {
  // Fixed leading columns, then every trace key any selector produced (sorted, stable).
  std::set<std::string> keys;
  for (const auto& row : tracker.trace()) {
    for (const auto& [k, v] : row.decision.trace) keys.insert(k);
  }
  OutputFile output(file);
  std::ostream& out = output.stream();
  out << "time,frame,selector,decision,reason,frames_since_keyframe";
  for (const auto& k : keys) out << ',' << k;
  out << '\n';
  const std::string selector(tracker.selector().name());
  for (const auto& row : tracker.trace()) {
    out << fmt::format("{:.9f},{},{},{},{},{}", static_cast<double>(row.t_ns) * 1e-9, row.frame_id,
                       selector, row.decision.insert ? 1 : 0, row.decision.reason,
                       row.frames_since_keyframe);
    for (const auto& k : keys) {
      out << ',';
      if (auto it = row.decision.trace.find(k); it != row.decision.trace.end()) {
        out << fmt::format("{:.6g}", it->second);
      }
    }
    out << '\n';
  }
  output.Commit();
}

// One row per frame the tracker saw (the viewer's timeline): time, frame id, tracking state,
// map points tracked (pose inliers), keyframe flag, tracking time.
void WriteFramesCsv(const Tracker& tracker, const std::filesystem::path& file) {
  OutputFile output(file);
  std::ostream& out = output.stream();
  out << "time,frame,state,tracked_points,keyframe,tracking_ms\n";
  for (const FrameRecord& r : tracker.records()) {
    out << fmt::format("{:.9f},{},{},{},{},{:.3f}\n", static_cast<double>(r.t_ns) * 1e-9,
                       r.frame_id, TrackingStateName(r.state), r.inliers, r.keyframe ? 1 : 0,
                       r.tracking_ms);
  }
  output.Commit();
}

// Every tracked frame's matched map points as 2-D tracks (io/track_file.h; --frame-tracks):
// frames numbered in order, tracks = map point ids, undistorted pixels of the tracking camera.
void WriteFrameTracks(const SlamSystem& system, const std::filesystem::path& file) {
  TrackSet tracks;
  tracks.camera = system.rig().intrinsics();
  tracks.camera.bf = 0;
  tracks.width = system.rig().camera.width();
  tracks.height = system.rig().camera.height();
  int frame = 0;
  for (const FrameRecord& r : system.tracker().records()) {
    if (r.observations.empty()) continue;
    std::vector<FrameRecord::Observation> sorted = r.observations;
    std::sort(sorted.begin(), sorted.end(),
              [](const auto& a, const auto& b) { return a.point < b.point; });
    for (std::size_t i = 0; i < sorted.size(); ++i) {
      if (i > 0 && sorted[i].point == sorted[i - 1].point) continue;
      tracks.observations.push_back({frame, static_cast<double>(r.t_ns) * 1e-9,
                                     static_cast<int>(sorted[i].point), sorted[i].u, sorted[i].v});
    }
    ++frame;
  }
  WriteTrackFile(tracks, file);
}

void WriteLoopEvents(JsonWriter* json, std::string_view key, const std::vector<LoopEvent>& events) {
  json->Key(key).BeginArray();
  for (const LoopEvent& e : events) {
    json->BeginObject();
    json->Member("time_s", static_cast<double>(e.t_ns) * 1e-9);
    json->Member("keyframe", static_cast<int>(e.query));
    json->Member("matched_keyframe", static_cast<int>(e.matched));
    json->Member("map", static_cast<int>(e.map));
    json->Member("matched_map", static_cast<int>(e.matched_map));
    json->Member("matches", e.matches);
    json->Member("correction_m", e.correction_m);
    json->Member("detection_ms", e.detection_ms);
    json->Member("correction_ms", e.correction_ms);
    json->Member("global_ba_ms", e.global_ba_ms);
    json->EndObject();
  }
  json->EndArray();
}

// Loops, merges (loop closing's record `stats`) and relocalisations / new maps (tracking
// states: RECENTLY_LOST -> OK is a relocalisation; giving up, `lost_for_good_s`, starts a new
// map or resets).
void WriteLoopClosing(const SlamSystem& system, const RunOptions& options,
                      const LoopClosingStats& stats, const std::vector<double>& lost_for_good_s,
                      JsonWriter* json) {
  std::vector<double> relocalisations;
  const auto& records = system.tracker().records();
  for (std::size_t i = 1; i < records.size(); ++i) {
    if (records[i].state == TrackingState::kOk &&
        records[i - 1].state == TrackingState::kRecentlyLost) {
      relocalisations.push_back(static_cast<double>(records[i].t_ns) * 1e-9);
    }
  }
  json->Key("loop_closing").BeginObject();
  json->Member("enabled", !options.system.no_loop);
  json->Member("num_loops", static_cast<int>(stats.loops.size()));
  json->Member("num_merges", static_cast<int>(stats.merges.size()));
  json->Member("num_relocalisations", static_cast<int>(relocalisations.size()));
  WriteLoopEvents(json, "loops", stats.loops);
  WriteLoopEvents(json, "merges", stats.merges);
  WriteArray(json, "relocalisation_times_s", relocalisations);
  WriteArray(json, "new_map_or_reset_times_s", lost_for_good_s);
  json->Member("tested_candidates", stats.tested_candidates);
  json->Member("verified_candidates", stats.verified_regions);
  json->Member("unconfirmed_candidates", stats.rejected_regions);
  json->Member("rejected_inertial_loops", stats.rejected_inertial);
  json->Member("rejected_implausible_loops", stats.rejected_implausible);
  json->Member("global_ba_started", stats.global_ba_started);
  json->Member("global_ba_finished", stats.global_ba_finished);
  json->Member("global_ba_aborted", stats.global_ba_aborted);
  json->Member("median_detection_ms", Median(stats.detection_ms));
  json->EndObject();
}

// What the run can tell about its own trajectory (system/estimate_health.h).
void WriteEstimateHealth(const EstimateHealth& health, JsonWriter* json) {
  json->Key("estimate").BeginObject();
  json->Member("suspect", health.suspect());
  json->Member("lost_for_good", static_cast<int>(health.lost_for_good_s.size()));
  json->Member("maps_at_end", health.maps_at_end);
  json->Member("largest_merge_correction_m", health.largest_merge_correction_m);
  json->Member("no_estimate", health.no_estimate);
  WriteStrings(json, "warnings", health.warnings);
  json->EndObject();
}

// Localisation only: how much of the run found itself in the loaded map, and each stretch
// without a pose (the run starts in one, before the first relocalisation).
void WriteLocalisation(const std::vector<FrameRecord>& records, JsonWriter* json) {
  const std::vector<LocalisationGap> gaps = LocalisationGaps(records);
  const int localised = static_cast<int>(std::count_if(
      records.begin(), records.end(), [](const FrameRecord& r) { return r.state == TrackingState::kOk; }));
  const double t0 = records.empty() ? 0.0 : static_cast<double>(records.front().t_ns) * 1e-9;
  std::optional<double> first_localised_s;
  for (const FrameRecord& r : records) {
    if (r.state == TrackingState::kOk) {
      first_localised_s = static_cast<double>(r.t_ns) * 1e-9 - t0;
      break;
    }
  }
  for (const LocalisationGap& g : gaps) {
    if (g.relocalised_s) {
      PKSLAM_LOG_INFO("localisation: no pose from t = {:.3f} s for {} frame(s), relocalised in "
                      "the loaded map at t = {:.3f} s",
                      g.begin_s, g.frames, *g.relocalised_s);
    } else {
      PKSLAM_LOG_WARN("localisation: no pose from t = {:.3f} s to the end ({} frame(s)): not "
                      "relocalised in the loaded map",
                      g.begin_s, g.frames);
    }
  }
  json->Key("localisation").BeginObject();
  json->Member("frames", static_cast<int>(records.size()));
  json->Member("localised", localised);
  // Of those, frames placed by visual odometry from the frame before (no map points in view).
  json->Member("visual_odometry", static_cast<int>(std::count_if(
                                      records.begin(), records.end(),
                                      [](const FrameRecord& r) { return r.visual_odometry; })));
  json->Member("first_localised_after_s", first_localised_s.value_or(-1.0));
  json->Member("gaps", static_cast<int>(gaps.size()));
  json->Member("unrecovered_frames",
               gaps.empty() || gaps.back().relocalised_s ? 0 : gaps.back().frames);
  json->EndObject();
}

// What the run found wrong with its input (system/input_report.h).
void WriteInputReport(const InputReport& input, JsonWriter* json) {
  json->Key("input").BeginObject();
  json->Member("frames_skipped", input.frames_skipped);
  json->Member("timestamp_jumps", input.timestamp_jumps);
  json->Member("imu_gaps", input.imu_gaps);
  json->Member("frames_without_imu", input.frames_without_imu);
  json->Member("frames_without_depth", input.frames_without_depth);
  WriteStrings(json, "warnings", input.warnings);
  json->EndObject();
}

}  // namespace

void RemoveRunOutputs(const std::filesystem::path& out) {
  // Every file WriteRunOutputs and WriteInertialOutputs may write (run.log is truncated by its
  // logger).
  static constexpr const char* kOutputs[] = {
      "trajectory.txt",  "trajectory_body.txt", "trajectory_online_body.txt",
      "keyframes.txt",   "keyframes_imu.csv",   "body_from_camera.txt",
      "map_points.ply",  "sparse_model.txt",    "keyframe_trace.csv",
      "frames.csv",      "frame_tracks.txt",    "stats.json",
      kPartialTrajectory};
  std::vector<std::filesystem::path> files;
  for (const char* name : kOutputs) files.push_back(out / name);
  // WriteInertialOutputs' keyframe chains, one per IMU initialisation stage.
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(out, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with("imu_stage") && name.ends_with("_keyframes_body.txt")) {
      files.push_back(entry.path());
    }
  }
  for (const auto& file : files) {
    std::filesystem::remove(file, ec);
    if (ec) {
      throw Error(
          fmt::format("cannot remove the earlier run's {}: {}", file.string(), ec.message()));
    }
  }
}

int WriteTrajectoryOutputs(const SlamSystem& system, const RunOptions& options) {
  const auto& out = options.out;
  const Trajectory frames = system.FrameTrajectory();
  WriteTrajectory(frames, out / "trajectory.txt", TrajectoryFormat::kTum);
  // The same poses for the body (IMU) frame, comparable with EuRoC ground truth. That applies
  // the metric camera-body lever arm to map units: right for metric maps, wrong for
  // visual-only monocular ones (after a Sim(3) alignment of scale s the lever arm counts s
  // times), so those get no body trajectory. They are evaluated on camera poses against the
  // ground truth moved into the camera (pkslam eval --body-from-camera, the bench,
  // cloud-compare), which needs the extrinsic.
  if (options.system.sensor != Sensor::kMonocular) {
    Trajectory body = frames;
    const SE3d camera_from_body = system.rig().body_from_camera.Inverse();
    for (auto& p : body.poses) p.pose = p.pose * camera_from_body;
    WriteTrajectory(body, out / "trajectory_body.txt", TrajectoryFormat::kTum);
  }
  return static_cast<int>(frames.poses.size());
}

namespace {

// What the frame records say, gathered once for the summary and stats.json.
struct FrameTimes {
  std::vector<double> tracking_ms;
  std::vector<double> tracking_cpu_ms;
  std::vector<double> build_cpu_ms;
  std::map<std::string, int> states;  // frames per tracking state
  bool initialised = false;
  int lost = 0;  // frames not tracked after the first initialisation
};

FrameTimes SummariseFrames(const std::vector<FrameRecord>& records) {
  FrameTimes frames;
  for (const FrameRecord& r : records) {
    frames.tracking_ms.push_back(r.tracking_ms);
    frames.tracking_cpu_ms.push_back(r.tracking_cpu_ms);
    frames.build_cpu_ms.push_back(r.build_cpu_ms);
    ++frames.states[TrackingStateName(r.state)];
    if (r.state != TrackingState::kNotInitialized) frames.initialised = true;
    if (frames.initialised && r.state != TrackingState::kOk) ++frames.lost;
  }
  return frames;
}

// The files beside the trajectory: keyframes, map, traces, inertial outputs.
void WriteMapOutputs(const SlamSystem& system, const RunOptions& options) {
  const auto& out = options.out;
  // A EuRoC recording's ground truth is the body (IMU); settings without IMU.T_b_c1 (ORB-SLAM2
  // stereo files, visual-only ones) give no way there, so the "body" is the camera.
  if (options.system.sensor != Sensor::kMonocular && !system.settings().body_from_cam0 &&
      std::filesystem::exists(options.dataset / "mav0")) {
    PKSLAM_LOG_WARN("{}: no camera-IMU extrinsic (IMU.T_b_c1), so trajectory_body.txt holds the "
                    "camera's poses; compare trajectory.txt with `pkslam eval "
                    "--body-from-camera` and the dataset's cam0 T_BS, or add IMU.T_b_c1",
                    options.settings ? options.settings->string() : std::string("settings"));
  }
  WriteRigidTransform(system.rig().body_from_camera, out / "body_from_camera.txt",
                      "body_from_camera (row-major 4x4, metres)");
  WriteTrajectory(system.KeyFrameTrajectory(), out / "keyframes.txt", TrajectoryFormat::kTum);
  system.WriteMapPly(out / "map_points.ply");
  WriteSparseModel(BuildSparseModel(system), out / "sparse_model.txt");
  if (options.system.trace) WriteTrace(system.tracker(), out / "keyframe_trace.csv");
  WriteFramesCsv(system.tracker(), out / "frames.csv");
  if (options.system.frame_tracks) WriteFrameTracks(system, out / "frame_tracks.txt");
  WriteInertialOutputs(system, out);
}

// The summary's counts and the estimate's health (warnings and errors logged).
void AssessRun(const SlamSystem& system, const RunOptions& options, const FrameTimes& frames,
               const LoopClosingStats& loop_stats, int frames_in_trajectory, RunSummary* summary) {
  const auto& records = system.tracker().records();
  summary->keyframes = system.NumKeyFrames();
  summary->map_points = system.NumMapPoints();
  summary->maps = system.NumMaps();
  summary->lost = frames.lost;
  summary->median_tracking_ms = Median(frames.tracking_ms);
  // Localisation never starts or resets a map: its losses are gaps in one map's trajectory,
  // reported as such (WriteLocalisation), not stitched maps.
  const bool localise_only = options.system.tracking.localise_only;
  summary->estimate =
      AssessEstimate(localise_only ? std::vector<double>{} : LostForGoodTimes(records),
                     loop_stats.merges, summary->maps);
  for (const std::string& w : summary->estimate.warnings)
    PKSLAM_LOG_WARN("suspect estimate: {}", w);
  summary->estimate.no_estimate =
      NoEstimateReason(static_cast<int>(records.size()), frames_in_trajectory, !frames.initialised,
                       IsMonocular(options.system.sensor));
  if (!summary->estimate.no_estimate.empty()) {
    PKSLAM_LOG_ERROR("no estimate: {}", summary->estimate.no_estimate);
  }
}

// The calibration estimate against the files it came from: warnings, OUT/calibration/.
void ReportCalibration(const SlamSystem& system, const RunOptions& options, RunSummary* summary) {
  const CalibrationSources sources =
      options.settings ? SourcesFromSettingsFile(*options.settings)
      : std::filesystem::exists(options.dataset / "mav0")
          ? SourcesFromEurocDataset(options.dataset)
          : SourcesFromSettingsFile(options.dataset / "settings.yaml");
  summary->calibration = system.calibration_report();
  summary->calibration_warnings = CalibrationWarnings(summary->calibration, sources);
  for (const std::string& w : summary->calibration_warnings) PKSLAM_LOG_WARN("{}", w);
  WriteCalibrationFiles(summary->calibration, system.settings(), options.out);
}

void WriteMapFileJson(JsonWriter* json, const char* key,
                      const std::optional<std::filesystem::path>& file,
                      const std::optional<SlamSystem::MapFileInfo>& info) {
  if (!file || !info) return;
  json->Key(key).BeginObject();
  json->Member("file", file->string());
  json->Member("maps", info->maps);
  json->Member("keyframes", info->keyframes);
  json->Member("map_points", info->map_points);
  json->Member("bytes", static_cast<std::int64_t>(info->bytes));
  json->Member("seconds", info->seconds);
  json->EndObject();
}

// stats.json: what ran on what, map files, input and estimate health.
void WriteRunJson(const RunOptions& options, const RunSummary& summary,
                  const std::vector<FrameRecord>& records, JsonWriter* json) {
  json->Member("dataset", options.dataset.string());
  json->Member("dataset_fingerprint", summary.dataset_fingerprint);
  json->Member("sensor", SensorName(options.system.sensor));
  json->Member("selector", options.system.selector);
  json->Member("deterministic", options.system.deterministic);
  json->Member("interrupted", summary.interrupted);
  json->Member("localise_only", options.system.tracking.localise_only);
  WriteMapFileJson(json, "map_loaded", options.load_map, summary.map_loaded);
  WriteMapFileJson(json, "map_saved", options.save_map, summary.map_saved);
  json->Member("degraded", summary.input.degraded());
  WriteInputReport(summary.input, json);
  WriteEstimateHealth(summary.estimate, json);
  if (options.system.tracking.localise_only) WriteLocalisation(records, json);
}

// stats.json: frames, keyframes (created, culled, declined, by reason), points, maps, states.
void WriteCountsJson(const RunSummary& summary, const FrameTimes& frames, int frames_in_trajectory,
                     const LocalMappingStats& mapping, const std::vector<FrameRecord>& records,
                     JsonWriter* json) {
  json->Member("frames", summary.frames);
  json->Member("frames_in_trajectory", frames_in_trajectory);
  json->Member("lost_frames", frames.lost);
  json->Member("keyframes", summary.keyframes);
  json->Member("keyframes_created",
               static_cast<int>(std::count_if(records.begin(), records.end(),
                                              [](const FrameRecord& r) { return r.keyframe; })));
  json->Member("keyframes_culled", mapping.keyframes_culled);
  // The keyframe queue's bound (LocalMappingOptions::max_queued_keyframes): its longest length
  // and the keyframes tracking declined because it was full.
  json->Member("max_queued_keyframes", mapping.max_queued_keyframes);
  json->Member("keyframes_declined_queue_full", summary.keyframes_declined_queue_full);
  // Which rule of the selector created how many keyframes ("initialisation": a map's first
  // keyframe(s), not a selector decision).
  json->Key("keyframe_reasons").BeginObject();
  for (const auto& [reason, count] : summary.keyframe_reasons) json->Member(reason, count);
  json->EndObject();
  // On how many of the frames the selector decided on each of its criteria held (pks and
  // pks-released: criterion1 = D_c > Th_adaptive, criterion2 = ECOG > |COG|).
  json->Key("selector_criteria").BeginObject();
  json->Member("decisions", summary.selector_decisions);
  for (const auto& [criterion, count] : summary.criteria_held) json->Member(criterion, count);
  json->EndObject();
  json->Member("map_points", summary.map_points);
  json->Member("maps", summary.maps);
  json->Key("tracking_states").BeginObject();
  for (const auto& [name, count] : frames.states) json->Member(name, count);
  json->EndObject();
}

// stats.json: wall and CPU time per thread, local mapping's statistics, memory.
void WriteTimingJson(const RunOptions& options, const RunSummary& summary, const FrameTimes& frames,
                     const LocalMappingStats& mapping, JsonWriter* json) {
  json->Member("wall_time_s", summary.wall_s);
  json->Member("sequence_duration_s", summary.sequence_s);
  json->Member("realtime_factor", summary.wall_s > 0 ? summary.sequence_s / summary.wall_s : 0.0);
  json->Member("median_tracking_ms", summary.median_tracking_ms);
  json->Member("p95_tracking_ms", Quantile(frames.tracking_ms, 0.95).value_or(0.0));
  // Offline runs (live emulation): wall time tracking waited for local mapping's state; it
  // is not part of tracking_ms.
  json->Member("mapping_wait_s", 1e-3 * mapping.live_wait_ms);
  json->Member("median_local_mapping_ms", Median(mapping.keyframe_ms));
  json->Member("local_ba_aborted", mapping.ba_aborted);
  json->Member("inertial_ba_with_prior", mapping.inertial_ba_with_prior);
  json->Member("inertial_ba_fixed_anchor", mapping.inertial_ba_fixed_anchor);
  json->Member("gravity_refinement_enabled", options.system.mapping.inertial.gravity_refinement);
  json->Member("inertial_search",
               TrackingOptions::InertialSearchName(options.system.tracking.inertial_search));
  json->Key("gravity_refinements").BeginArray();
  for (const GravityRefinementStat& g : mapping.gravity_refinements) {
    json->BeginObject();
    json->Member("t_s", static_cast<double>(g.t_ns) * 1e-9);
    json->Member("keyframes", g.keyframes);
    json->Member("tilt_observability", g.observability);
    json->Member("tilt_change_mrad", 1e3 * g.tilt_change_rad);
    json->Member("ms", g.ms);
    json->EndObject();
  }
  json->EndArray();
  json->Member("gravity_refinements_dropped", mapping.gravity_refinements_dropped);
  // CPU time (independent of the machine's load): per-thread sums and medians.
  const auto sum = [](const std::vector<double>& v) {
    return std::accumulate(v.begin(), v.end(), 0.0);
  };
  json->Member("process_cpu_s", ProcessCpuSeconds());
  json->Member("tracking_cpu_s", 1e-3 * (sum(frames.tracking_cpu_ms) + sum(frames.build_cpu_ms)));
  json->Member("median_tracking_cpu_ms", Median(frames.tracking_cpu_ms));
  json->Member("median_build_cpu_ms", Median(frames.build_cpu_ms));
  json->Member("local_mapping_cpu_s", 1e-3 * sum(mapping.keyframe_cpu_ms));
  json->Member("median_local_mapping_cpu_ms", Median(mapping.keyframe_cpu_ms));
  json->Member("median_local_ba_cpu_ms", Median(mapping.ba_cpu_ms));
  json->Member("peak_memory_mib", PeakMemoryMiB());
}

// stats.json: exclusive holds of the map lock per kind of change (map_model/map_editor.h): how
// often and how long (wall) each kind kept the other threads out of the map.
void WriteMapEditsJson(const SlamSystem& system, JsonWriter* json) {
  json->Key("map_edits").BeginObject();
  const MapEditTable edits = system.atlas().EditStats();
  for (int k = 0; k < kNumMapEdits; ++k) {
    const MapEditStats& e = edits[static_cast<std::size_t>(k)];
    if (e.holds == 0) continue;
    json->Key(std::string(MapEditName(static_cast<MapEdit>(k)))).BeginObject();
    json->Member("holds", e.holds);
    json->Member("total_ms", 1e3 * e.total_s);
    json->Member("max_ms", 1e3 * e.max_s);
    json->EndObject();
  }
  json->EndObject();
}

// stats.json: the per-frame and per-keyframe series.
void WriteSeriesJson(const FrameTimes& frames, const LocalMappingStats& mapping, JsonWriter* json) {
  WriteArray(json, "tracking_ms", frames.tracking_ms);
  WriteArray(json, "local_mapping_ms", mapping.keyframe_ms);
  WriteArray(json, "local_ba_ms", mapping.ba_ms);
  WriteArray(json, "tracking_cpu_ms", frames.tracking_cpu_ms);
  WriteArray(json, "build_cpu_ms", frames.build_cpu_ms);
  WriteArray(json, "local_mapping_cpu_ms", mapping.keyframe_cpu_ms);
  WriteArray(json, "local_ba_cpu_ms", mapping.ba_cpu_ms);
  // Per keyframe: [keyframes, triangulation keypoints, fused projections, solver residuals]
  // (core/util/work_meter.h), what live emulation's work clock prices.
  json->Key("local_mapping_work").BeginArray();
  for (const WorkCounts& w : mapping.keyframe_work) {
    json->BeginArray();
    for (std::int64_t units : w) json->Value(units);
    json->EndArray();
  }
  json->EndArray();
}

}  // namespace

void WriteRunOutputs(const SlamSystem& system, const RunOptions& options, RunSummary* summary) {
  // The trajectory first: when a later file fails (full disk) or a second signal ends the
  // process, the most valuable output is already complete.
  const int frames_in_trajectory = WriteTrajectoryOutputs(system, options);
  WriteMapOutputs(system, options);
  const auto& records = system.tracker().records();
  const FrameTimes frames = SummariseFrames(records);
  const LocalMappingStats mapping = system.mapping_stats();
  const LoopClosingStats loop_stats = system.loop_stats();
  AssessRun(system, options, frames, loop_stats, frames_in_trajectory, summary);
  ReportCalibration(system, options, summary);

  JsonWriter json;
  json.BeginObject();
  WriteRunJson(options, *summary, records, &json);
  WriteCountsJson(*summary, frames, frames_in_trajectory, mapping, records, &json);
  WriteTimingJson(options, *summary, frames, mapping, &json);
  WriteMapEditsJson(system, &json);
  WriteLoopClosing(system, options, loop_stats, summary->estimate.lost_for_good_s, &json);
  WriteCalibrationJson(summary->calibration, summary->calibration_warnings, &json);
  WriteSeriesJson(frames, mapping, &json);
  json.EndObject();
  WriteFileAtomically(options.out / "stats.json", json.str() + '\n');
}

}  // namespace pkslam
