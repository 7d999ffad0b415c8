// Runs the SLAM system over a dataset on disk (EuRoC ASL or TUM RGB-D layout) and writes the
// run's outputs. Used by `pkslam run` and `pkslam bench`.
//
// OUT/trajectory.txt   every tracked frame, TUM format (seconds), camera pose world_from_camera
// OUT/trajectory_body.txt  the same as body (IMU) poses world_from_body (ground truth's frame)
// OUT/keyframes.txt    keyframes of the final map, same format
// OUT/map_points.ply   map points (binary PLY)
// OUT/sparse_model.txt keyframes with keypoints and map points with observations
//                      (io/sparse_model.h; for `pkslam export-colmap`)
// OUT/stats.json       timings, counts, tracking states, memory
// OUT/run.log          the log of the run
// OUT/keyframe_trace.csv  per-frame keyframe decisions (with trace enabled)
// OUT/frames.csv       per frame: time, tracking state, tracked map points, keyframe flag,
//                      tracking time (the viewer's timeline)
// OUT/trajectory.txt.partial  online poses appended frame by frame while the run goes; left
//                      only by a run that did not finish (SIGKILL, crash)
// (system/run_outputs.h lists them again to clear them before a re-run into the same OUT.)
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "io/euroc_dataset.h"
#include "system/estimate_health.h"
#include "system/input_report.h"
#include "system/slam_system.h"

namespace pkslam {

struct RunOptions {
  std::filesystem::path dataset;
  // ORB-SLAM3 settings file; when absent: EuRoC datasets use their sensor.yaml files, other
  // layouts look for settings.yaml in the dataset directory.
  std::optional<std::filesystem::path> settings;
  // Vocabulary (DBoW2 text or pkslam binary); default: the one shipped in Vocabulary/.
  std::optional<std::filesystem::path> vocabulary;
  std::filesystem::path out = "out";
  // Pace frames to their timestamps instead of running as fast as possible.
  bool realtime = false;
  // Skip the dataset's first frames (a slice of a sequence: --first-frame), then stop after
  // max_frames of the rest (0: all).
  int first_frame = 0;
  int max_frames = 0;
  // Map files (--load-map, --save-map; map_model/storage/map_file.h). Localisation only
  // (system.tracking.localise_only) needs load_map.
  std::optional<std::filesystem::path> load_map;
  std::optional<std::filesystem::path> save_map;
  // SystemOptions::mapping_sync; empty: "live" for offline runs, "free" with `realtime`.
  std::string mapping_sync;
  // No progress line.
  bool quiet = false;
  // Inertial sensors: frames the IMU does not cover are an error unless this is set (then a
  // warning, and the run is flagged degraded).
  bool allow_imu_gaps = false;
  // KITTI sequences: the colour pair (image_2, image_3) instead of the grey one.
  bool kitti_colour = false;
  // Plausibility limits of IMU samples (EuRoC reader).
  ImuLimits imu_limits;
  SystemOptions system;

  void Check() const;
};

struct RunSummary {
  int frames = 0;
  int tracked = 0;
  int lost = 0;  // frames without a pose after initialisation
  int keyframes = 0;
  int map_points = 0;
  int maps = 0;
  double wall_s = 0;
  double sequence_s = 0;
  double median_tracking_ms = 0;
  bool interrupted = false;
  // Map files read and written (sizes, counts, wall seconds).
  std::optional<SlamSystem::MapFileInfo> map_loaded;
  std::optional<SlamSystem::MapFileInfo> map_saved;
  std::string dataset_fingerprint;  // io/dataset_fingerprint.h
  // Keyframes created, per reason: the selector rule that fired, or "initialisation".
  std::map<std::string, int> keyframe_reasons;
  // Keyframes the selector wanted while local mapping's queue was full (declined).
  int keyframes_declined_queue_full = 0;
  // Frames the selector decided on, and on how many of them each criterion held
  // (TrackResult::criteria_held).
  int selector_decisions = 0;
  std::map<std::string, int> criteria_held;
  // What was wrong with the input without stopping the run (degraded() when anything was).
  InputReport input;
  // What the run's own signals say about its trajectory (suspect() when tracking was lost for
  // good or maps stayed apart).
  EstimateHealth estimate;
  // The run's calibration (file, estimate, sigmas, adjustments) and its warnings.
  CalibrationReport calibration;
  std::vector<std::string> calibration_warnings;

  // Adds one tracked frame: frames, tracked, keyframe reasons, selector decisions, criteria.
  void Count(const TrackResult& result);
};

// Sleeps until `due` in short slices, returning early once `interrupt` (may be null) is set:
// --realtime pacing that Ctrl-C or SIGTERM ends promptly.
void SleepUntilOrInterrupted(std::chrono::steady_clock::time_point due,
                             const std::atomic<bool>* interrupt);

// The vocabulary shipped with pkslam (Vocabulary/ in the source tree or next to the binary).
std::filesystem::path DefaultVocabularyPath();
// The run's vocabulary (--vocabulary or the default); InputError naming a missing file.
std::shared_ptr<const Vocabulary> LoadRunVocabulary(const RunOptions& options);

// How a caller stops and follows a run (every member optional).
struct RunControl {
  // Polled between frames (set by a signal handler or another thread): the run stops and
  // still writes its outputs for the frames processed.
  const std::atomic<bool>* interrupt = nullptr;
  // Called once, just before the first frame, when the input has been read and checked: from
  // then on `interrupt` is polled (before, reading a dataset may take a while and a caller
  // should let a signal end the process).
  std::function<void()> frames_starting;
  // Called once trajectory.txt holds every frame processed, before the shutdown of local
  // mapping and loop closing and the other outputs (apps/cmd_run.cc lets a second Ctrl-C end
  // the process from then on).
  std::function<void()> trajectory_written;
  // Called on the tracking thread after every frame with the system, the frame's result and its
  // (left / only) image: a live view copies what it shows. Unset: no cost.
  std::function<void(const SlamSystem&, const TrackResult&, const cv::Mat& image,
                     std::int64_t t_ns)>
      frame_tracked;
  // Called once the run has stopped tracking (before the outputs are written).
  std::function<void()> tracking_finished;
};

// Throws InputError / OptionError on bad input, OutputError when an output cannot be written.
RunSummary RunDataset(const RunOptions& options, const RunControl& control = {});

}  // namespace pkslam
