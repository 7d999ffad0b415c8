// The SLAM system: owns the Atlas, the tracker (caller's thread), the LocalMapping thread and
// the LoopClosing thread, and turns the map into outputs. One instance per run.
#pragma once

#include <atomic>
#include <filesystem>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "core/bow/vocabulary.h"
#include "estimators/calibration/calibration_bundle.h"
#include "system/calibration_outputs.h"
#include "io/settings.h"
#include "io/trajectory.h"
#include "loopclosing/loop_closing.h"
#include "map_model/atlas.h"
#include "mapping/local_mapper.h"
#include "system/rig_factory.h"
#include "tracking/tracker.h"

namespace pkslam {

struct SystemOptions {
  Sensor sensor = Sensor::kStereo;
  // Keyframe selector name and parameters (merged over the settings' Keyframe.* values).
  std::string selector = "orbslam3";
  std::map<std::string, double> selector_parameters;
  // Fixed seeds, local mapping in lock-step with tracking, single-threaded solvers.
  bool deterministic = false;
  // Run seed (--seed): passed to tracking and loop closing, so repeated research runs draw
  // different RANSAC samples; combined with `deterministic` each seed is reproducible.
  std::uint64_t seed = 0;
  // How tracking meets local mapping: "live" (local mapping's state as a live run at
  // real-time pace would see it; LocalMapper::AcceptsKeyFramesAt), "lockstep" (each keyframe
  // mapped before the next frame; forced by `deterministic`), "free" (no coupling: what a
  // live run does, and what --realtime uses).
  std::string mapping_sync = "free";
  // --calibrate online: where each calibration adjustment solves. "auto": in a thread of its own
  // beside local mapping (which never stops for it), except under "lockstep", where it solves
  // inside local mapping's keyframe step; under "live" on the work clock the thread is paced,
  // its result applied where its counted work makes it due, so offline runs repeat
  // (docs/calibration.md, "When" and "Cost"); "thread" / "step" force one.
  std::string calibration_thread = "auto";
  // "live": playback speed of the emulated live run (1: frames at their timestamps; 2: twice
  // as fast, so local mapping's work spans twice as much data time).
  double live_pace = 2.0;
  // "live": the clock local mapping's work is measured in (mapping/local_mapper.h LiveClock):
  // "work" (units of work at a reference machine's prices: the same result on every machine),
  // "cpu" (its thread's CPU time: this machine however loaded) or "wall" (this machine as
  // loaded).
  std::string live_clock = "work";
  // Record per-frame keyframe decisions (keyframe_trace.csv).
  bool trace = false;
  // Record each tracked frame's matched map points (RUN/frame_tracks.txt).
  bool frame_tracks = false;
  TrackingOptions tracking;
  LocalMappingOptions mapping;
  // --no-loop: no loop closing and no map merging.
  bool no_loop = false;
  LoopClosingOptions loop;

  void Check() const;
};

class SlamSystem {
 public:
  SlamSystem(const Settings& settings, std::shared_ptr<const Vocabulary> vocabulary,
             SystemOptions options);
  ~SlamSystem();
  SlamSystem(const SlamSystem&) = delete;
  SlamSystem& operator=(const SlamSystem&) = delete;

  // Raw (unrectified) or rectified stereo pair, as the settings describe the rig. Inertial
  // sensors: `t_ns` is the image stamp; the frame is tracked (and written out) at
  // stamp + the camera-IMU time offset, on the IMU clock (IMU.TimeOffset, or its online
  // estimate), so IMU samples must reach past it (ImuLookaheadNs).
  TrackResult TrackStereo(const cv::Mat& left, const cv::Mat& right, std::int64_t t_ns);
  TrackResult TrackRgbd(const cv::Mat& image, const cv::Mat& depth, std::int64_t t_ns);
  TrackResult TrackMonocular(const cv::Mat& image, std::int64_t t_ns);
  // Inertial sensors: IMU samples (time-ordered) up to at least the next frame's time.
  void AddImu(const std::vector<ImuMeasurement>& samples) { tracker_->AddImu(samples); }
  // How far past an image stamp IMU samples must have been given before the image is tracked.
  std::int64_t ImuLookaheadNs() const;

  // Lets local mapping finish its queue and stops the threads (idempotent).
  void Shutdown();

  // Map files (map_model/storage/map_file.h). SaveMap writes the whole Atlas (call after
  // Shutdown for the final map). LoadMap restores a file into this new system before its
  // first frame: with tracking.localise_only the tracker relocalises into the loaded current
  // map and only tracks; otherwise a new map starts for this session and loop closing merges
  // it into a loaded one it recognises. Both throw InputError / OutputError naming the file.
  struct MapFileInfo {
    int maps = 0;
    int keyframes = 0;
    int map_points = 0;
    std::uintmax_t bytes = 0;
    double seconds = 0;  // wall time of the read + restore, or of the snapshot + write
  };
  MapFileInfo SaveMap(const std::filesystem::path& file) const;
  MapFileInfo LoadMap(const std::filesystem::path& file);

  // Camera poses (world_from_camera) of every tracked frame whose map is the largest map
  // (ORB-SLAM3's choice when saving), with poses re-expressed through their reference
  // keyframes' final poses. Frames without a pose are left out.
  Trajectory FrameTrajectory() const;
  Trajectory KeyFrameTrajectory() const;
  // Binary little-endian PLY of the largest map's points (x, y, z float; observations uchar).
  void WriteMapPly(const std::filesystem::path& file) const;

  const CameraRig& rig() const { return *setup_.rig; }
  // The calibration the settings state (the prior of online calibration).
  const RigCalibration& file_calibration() const { return file_calibration_; }
  const Settings& settings() const { return settings_; }
  // The run's calibration: the file's, the estimate at the end, every online adjustment, and
  // (online) the final whole-map adjustment's sigmas and gates (after Shutdown).
  CalibrationReport calibration_report() const;
  // Batch calibration refinement over the largest map (call after Shutdown): the calibration
  // bundle adjustment with `free` parameters, prior from the settings.
  CalibrationBundleResult RefineCalibration(const CalibrationFreedom& free,
                                            const CalibrationBundleOptions& options,
                                            int max_observations_per_keyframe) const;
  const Tracker& tracker() const { return *tracker_; }
  LocalMappingStats mapping_stats() const { return mapper_->stats(); }
  // Empty stats with --no-loop.
  LoopClosingStats loop_stats() const { return loop_ ? loop_->stats() : LoopClosingStats{}; }
  // The largest map's points and keyframes, copied under the Atlas lock (for the library).
  struct MapPointView {
    MapPointId id = 0;
    Eigen::Vector3d world_position = Eigen::Vector3d::Zero();
    int observations = 0;  // keyframes observing it
  };
  struct KeyFrameView {
    KeyFrameId id = 0;
    std::int64_t t_ns = 0;
    SE3d world_from_camera;
  };
  std::vector<MapPointView> MapPoints() const;
  std::vector<KeyFrameView> KeyFrames() const;
  // Localisation mode at run time (Tracker::SetLocaliseOnly): caller's thread, between frames.
  void SetLocalisationMode(bool on) { tracker_->SetLocaliseOnly(on); }
  bool localisation_mode() const { return tracker_->localise_only(); }
  // The last frame's pose inliers (Tracker::LastFrameInliers).
  std::vector<FrameRecord::Observation> TrackedObservations() const {
    return tracker_->LastFrameInliers();
  }
  // The keyframe selector's name and the parameters given to it (the settings' Keyframe.* with
  // the options' selector_parameters over them); others are at the selector's defaults.
  const std::string& selector_name() const { return options_.selector; }
  const std::map<std::string, double>& selector_parameters() const {
    return selector_parameters_;
  }
  // Keyframes and map points in the largest map; number of maps.
  int NumKeyFrames() const;
  int NumMapPoints() const;
  int NumMaps() const;

  // For output writers (system/sparse_model_builder.h): the Atlas (take its mutex shared to
  // read) and the map the outputs describe: the one with the most keyframes among the maps
  // of this session (a loaded map counts once merged with it or localised in).
  const Atlas& atlas() const { return atlas_; }
  const Map* LargestMap() const;  // requires the Atlas lock

 private:
  SystemOptions options_;
  std::map<std::string, double> selector_parameters_;  // as given to the selector
  Settings settings_;
  RigSetup setup_;
  RigCalibration file_calibration_;
  // Online calibration: the final whole-map adjustment (FinishCalibration, at Shutdown).
  std::optional<CalibrationBundleResult> final_calibration_;
  CalibrationGates final_gates_;
  std::string final_note_;  // why the final adjustment was not applied (reported)
  CalibrationReport::FinalTiming final_timing_;  // the final adjustment's wall time (reported)
  void FinishCalibration();
  // The camera-IMU time offset applied to frame stamps (inertial sensors): frames are tracked on
  // the IMU clock, stamp + offset.
  double time_offset_s_ = 0.0;
  std::int64_t ImuClock(std::int64_t t_ns) const;
  // Online calibration: the Atlas calibration version setup_ and the tracker follow; before each
  // frame SyncCalibration takes a newer one (tracking thread).
  int calibration_version_ = 0;
  void SyncCalibration();
  // The tracker's IMU samples corrected for `calibration`'s axis errors (inertial sensors).
  void SetTrackerImuAxisErrors(const RigCalibration& calibration);
  std::shared_ptr<const Vocabulary> vocabulary_;
  Atlas atlas_;
  std::unique_ptr<LocalMapper> mapper_;
  std::unique_ptr<LoopClosing> loop_;
  std::atomic<bool> mapper_finished_{false};  // read by loop closing's MappingControl
  std::unique_ptr<Tracker> tracker_;
  bool shut_down_ = false;
  // Keyframes with smaller ids came from a map file (LoadMap); see LargestMap.
  KeyFrameId session_first_keyframe_id_ = 0;
};

}  // namespace pkslam
