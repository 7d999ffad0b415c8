// The LocalMapping thread (ORB-SLAM3's LocalMapping): for each new keyframe it completes the
// point associations, culls recent points, triangulates new points with covisible keyframes,
// fuses duplicates, runs local bundle adjustment and culls redundant keyframes, then hands the
// keyframe on (to loop closing). This class is the thread, its bounded queue, the stop/reset
// handshakes and live emulation's pacing (mapping/live_timeline.h); the keyframe's steps are
// KeyFrameSteps (mapping/keyframe_steps.h), the whole-map inertial ones InertialStages, online
// calibration OnlineCalibrator.
//
// Threads: the queue and flags are guarded by `mutex_` (PKSLAM_GUARDED_BY, checked by Clang
// in CTest layering.thread_safety; plus atomics for flags read on hot paths); the map model by the
// Atlas mutex, taken shared for computation and exclusive for the short apply steps
// (docs/architecture.md). Owned by System; Stop() joins the thread.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <thread>
#include <vector>

#include "core/imu/imu_types.h"
#include "core/sensor/camera_rig.h"
#include "core/sensor/rig_calibration.h"
#include "core/util/annotated_mutex.h"
#include "core/util/work_meter.h"
#include "map_model/atlas.h"
#include "map_model/estimation/bundle_collect.h"
#include "map_model/mapping_backend.h"
#include "mapping/calibration_refinement.h"
#include "mapping/inertial_mapping.h"
#include "mapping/inertial_stages.h"
#include "mapping/keyframe_steps.h"
#include "mapping/live_timeline.h"
#include "mapping/local_mapping_options.h"
#include "mapping/online_calibrator.h"

namespace pkslam {

struct LocalMappingStats {
  std::vector<double> keyframe_ms;  // processing time per keyframe
  std::vector<double> ba_ms;        // local BA time per keyframe (0 when skipped)
  // CPU time of the mapping thread per keyframe, all of it and local BA alone (the wall-clock
  // times above also count lock waits and preemption on a busy machine).
  std::vector<double> keyframe_cpu_ms;
  std::vector<double> ba_cpu_ms;
  // Units of work per keyframe (core/util/work_meter.h), the measure of live emulation's work
  // clock; with keyframe_cpu_ms, the data its model is fitted to.
  std::vector<WorkCounts> keyframe_work;
  // Live emulation: total wall ms tracking waited in AcceptsKeyFramesAt.
  double live_wait_ms = 0;
  int ba_aborted = 0;
  // The longest the keyframe queue was (at most LocalMappingOptions::max_queued_keyframes).
  int max_queued_keyframes = 0;
  // Local inertial BAs whose anchor carried a marginalisation prior / was fixed.
  int inertial_ba_with_prior = 0;
  int inertial_ba_fixed_anchor = 0;
  int keyframes_culled = 0;
  int points_created = 0;
  int points_culled = 0;
  std::vector<ImuStageSnapshot> imu_stages;
  std::vector<GravityRefinementStat> gravity_refinements;
  int gravity_refinements_dropped = 0;  // results dropped: the map moved meanwhile
  std::vector<CalibrationRefinementStat> calibration_refinements;
};

class LocalMapper : public MappingBackend {
 public:
  LocalMapper(Atlas* atlas, std::shared_ptr<const CameraRig> rig, LocalMappingOptions options);
  ~LocalMapper() override;
  LocalMapper(const LocalMapper&) = delete;
  LocalMapper& operator=(const LocalMapper&) = delete;

  // Starts the thread. Without Start(), WaitUntilIdle() processes the queue inline.
  void Start();
  // Processes what is queued, then stops and joins the thread.
  void Finish();

  // Where processed keyframes go (loop closing); set before Start().
  void SetKeyFrameConsumer(std::function<void(const KeyFramePtr&)> consumer);
  // Online calibration (options.calibration.enabled): the calibration file's values (the prior)
  // and the rest of the rig, to build rigs of new estimates; set before Start().
  void SetCalibrationPrior(RigCalibration file, RigShape shape);

  // MappingBackend.
  void InsertKeyFrame(const KeyFramePtr& kf) override;
  bool AcceptsKeyFrames() const override { return accept_keyframes_.load(); }
  bool IsStoppedOrStopRequested() const override;
  bool IsInitializingImu() const override { return inertial_stages_.initializing(); }
  bool TakeSlowMotionFlag() override { return inertial_stages_.TakeSlowMotionFlag(); }
  int QueueSize() const override;
  bool QueueFull() const override;
  void InterruptBundleAdjustment() override { abort_ba_.store(true); }
  void WaitUntilIdle() override;
  bool AcceptsKeyFramesAt(std::int64_t t_ns) override;
  bool EmulatesLive() const override { return live_.on; }
  void NoteFrameTime(std::int64_t t_ns) override;
  // Offline runs: emulate a live run's timing (AcceptsKeyFramesAt); set before Start().
  // `pace`: playback speed of the emulated live run (2: frames arrive twice as fast as their
  // timestamps say, so mapping's work spans twice as much data time).
  // `clock`: how each keyframe's processing time is measured (LiveClock). CPU time halves on a
  // machine twice as fast and wall time also grows with the machine's load, so only the work
  // clock gives every machine the same offline result.
  // On the work clock local mapping is also paced: it changes the map at a data time only once
  // tracking has processed every earlier frame (NoteFrameTime), and tracking waits for it
  // (AcceptsKeyFramesAt), so each frame sees the map a live run on the reference machine would
  // show it, whatever the speed of this one or the number of its cores.
  void EmulateLive(bool on, double pace = 1.0, LiveClock clock = LiveClock::kWork);
  // Total wall ms AcceptsKeyFramesAt blocked.
  double live_wait_ms() const { return stats().live_wait_ms; }
  void ResetQueue() override;

  // Loop closing pauses local mapping while it corrects the map.
  void RequestStop();
  bool IsStopped() const;
  void Release();

  LocalMappingStats stats() const;

 private:
  void Run();
  bool HasQueued() const;
  // Live emulation on the work clock: blocks until tracking has reached the data time local
  // mapping's work has got to (or a stop, reset or finish is requested). Called by the mapping
  // thread with no map lock held: before each step that changes the map and after each solver
  // iteration (the work meter's pacer). No-op otherwise.
  void PaceToTracker();
  // PaceToTracker, then a calibration adjustment due by then (OnlineCalibrator::ApplyDue).
  void StepBoundary() {
    PaceToTracker();
    calibrator_.ApplyDue();
  }
  bool Paced() const { return live_.paced(); }
  // Takes the oldest queued keyframe and runs the steps on it.
  void ProcessNext();

  Atlas* atlas_;
  std::shared_ptr<const CameraRig> rig_;
  LocalMappingOptions options_;
  std::function<void(const KeyFramePtr&)> consumer_;

  mutable Mutex mutex_;  // guards the members marked PKSLAM_GUARDED_BY(mutex_)
  ConditionVariable wake_;
  ConditionVariable idle_;
  // Bounded by options_.max_queued_keyframes (InsertKeyFrame, QueueFull).
  std::deque<KeyFramePtr> queue_ PKSLAM_GUARDED_BY(mutex_);
  // The thread runs (from Start until Run returns): an insert into a full queue waits for it.
  bool running_ PKSLAM_GUARDED_BY(mutex_) = false;
  bool busy_ PKSLAM_GUARDED_BY(mutex_) = false;
  // Live emulation: the settings are set before Start() and read-only afterwards; the data
  // clock (where the current and the last keyframe's processing fall, tracking's data time)
  // is guarded.
  LiveEmulation live_;
  // Local mapping's work so far: added to by the mapping thread (its solvers' callbacks
  // included), read by tracking through the timeline's work clock.
  WorkMeter work_;
  LiveTimeline timeline_ PKSLAM_GUARDED_BY(mutex_);
  // Paced emulation: the condition local mapping waits on for tracking's data time to grow.
  ConditionVariable paced_;
  int idle_waiters_ PKSLAM_GUARDED_BY(mutex_) = 0;  // threads in WaitUntilIdle
  bool finish_requested_ PKSLAM_GUARDED_BY(mutex_) = false;
  bool stop_requested_ PKSLAM_GUARDED_BY(mutex_) = false;
  bool stopped_ PKSLAM_GUARDED_BY(mutex_) = false;
  bool reset_requested_ PKSLAM_GUARDED_BY(mutex_) = false;
  LocalMappingStats stats_ PKSLAM_GUARDED_BY(mutex_);

  std::atomic<bool> accept_keyframes_{true};
  std::atomic<bool> abort_ba_{false};

  // The per-keyframe work (mapping/keyframe_steps.h), run by the mapping thread.
  KeyFrameSteps steps_;

  // Online calibration's schedule and thread (mapping/online_calibrator.h), driven by the
  // mapping thread; Finish and the reset stop it.
  OnlineCalibrator calibrator_;
  // The IMU initialisation stages and gravity refinement (mapping/inertial_stages.h), driven
  // by the mapping thread.
  InertialStages inertial_stages_;

  std::thread thread_;
};

}  // namespace pkslam
