// The LocalMapping thread (ORB-SLAM3's LocalMapping): for each new keyframe it completes the
// point associations, culls recent points, triangulates new points with covisible keyframes,
// fuses duplicates, runs local bundle adjustment and culls redundant keyframes, then hands the
// keyframe on (to loop closing).
//
// Threads: the queue and flags are guarded by `mutex_` (PKSLAM_GUARDED_BY, checked by Clang
// in CTest layering.thread_safety; plus atomics for flags read on hot paths); the map model by the
// Atlas mutex, taken shared for computation and exclusive for the short apply steps
// (docs/architecture.md). Owned by System; Stop() joins the thread.
#pragma once

#include <time.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
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
#include "mapping/online_calibrator.h"
#include "mapping/recent_points.h"

namespace pkslam {

struct LocalMappingOptions {
  // Covisible keyframes used for triangulation (stereo/RGB-D, monocular).
  int triangulation_neighbours_stereo = 10;
  int triangulation_neighbours_mono = 20;
  // Keyframe culling: a keyframe is redundant when this share of its (close) points is seen
  // by at least `culling_observers` other keyframes at the same or a finer scale.
  double culling_redundancy = 0.9;
  int culling_observers = 3;
  bool cull_keyframes = true;
  // Recent points: culled when found/visible < this ratio.
  double min_found_ratio = 0.25;
  // The keyframe queue's bound (backpressure, MappingBackend::QueueFull): tracking declines a
  // keyframe while this many wait, and a keyframe it cannot decline (a new map's first two)
  // waits for room. ORB-SLAM3's rule already keeps the queue at 3 or fewer (it declines while
  // three wait, or while mapping is busy for monocular), so in ordinary runs the bound is
  // never reached; it holds for every selector and for mapping held by loop closing too.
  // At least 2: a map's initialisation inserts two keyframes at once.
  int max_queued_keyframes = 8;
  BundleAdjustmentOptions ba;
  // Inertial sensors: IMU initialisation stages and local inertial BA.
  InertialMappingOptions inertial;
  // Online calibration (mapping/calibration_refinement.h); off by default.
  OnlineCalibrationOptions calibration;

  void Check() const;
};

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

// How live emulation measures local mapping's work on a keyframe.
enum class LiveClock {
  // Units of work priced by kReferenceWork (core/util/work_meter.h): the same emulated machine
  // on every machine, loaded or not, fast or slow.
  kWork,
  // The mapping thread's CPU time: this machine, however loaded it is.
  kCpu,
  // Wall time: this machine under its present load.
  kWall,
};
// "work", "cpu" or "wall"; nullopt for anything else.
std::optional<LiveClock> ParseLiveClock(std::string_view name);

// The work clock's prices: CPU seconds per unit of work of local mapping on the machine the
// defaults were tuned on (2 cores, 2026-11; fitted to per-keyframe CPU times by
// evaluation/studies/coupling/fit_work_model.py, docs/speed.md "One core or two").
extern const WorkModel kReferenceWork;

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
  bool EmulatesLive() const override { return emulate_live_; }
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
  // Live emulation: data-clock nanoseconds spanned by `work_s` seconds of work (emulation clock).
  std::int64_t DataNs(double work_s) const;
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
  // Live emulation: the data time the current keyframe's processing has reached.
  std::int64_t LiveReachedNs() const PKSLAM_REQUIRES(mutex_);
  bool Paced() const { return emulate_live_ && live_clock_ == LiveClock::kWork; }
  void ProcessNext();
  void ProcessNewKeyFrame(const KeyFramePtr& kf);
  void CullRecentPoints(const KeyFramePtr& kf);
  void CreateNewMapPoints(const KeyFramePtr& kf);
  void SearchInNeighbours(const KeyFramePtr& kf);
  void LocalBundleAdjustment(const KeyFramePtr& kf);
  void CullKeyFrames(const KeyFramePtr& kf);

  // Local inertial BA once the map's IMU is initialised (mapping/local_mapper_inertial.cc);
  // false if it did not apply (then the visual local BA runs).
  bool LocalInertialBundleAdjustment(const KeyFramePtr& kf);

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
  // Live emulation: the switch and pace are set before Start() and read-only afterwards; the
  // data-clock time at which the last finished keyframe's processing ends, and the data-clock
  // start and emulation-clock start of the current one, are guarded.
  bool emulate_live_ = false;
  double live_pace_ = 1.0;
  std::int64_t live_free_ns_ PKSLAM_GUARDED_BY(mutex_) = std::numeric_limits<std::int64_t>::min();
  std::int64_t live_job_start_ns_ PKSLAM_GUARDED_BY(mutex_) = 0;
  LiveClock live_clock_ = LiveClock::kWork;
  // Local mapping's work so far: added to by the mapping thread (its solvers' callbacks
  // included), read by tracking through LiveClockSeconds.
  WorkMeter work_;
  // The mapping thread's CPU clock (set by Run() before it takes a keyframe).
  std::optional<clockid_t> mapping_cpu_clock_ PKSLAM_GUARDED_BY(mutex_);
  // The emulation clock (mapping CPU or wall seconds) when the current keyframe was taken.
  double live_job_clock_start_ PKSLAM_GUARDED_BY(mutex_) = 0;
  // Paced emulation: the data time of the frame tracking processes (every earlier one done),
  // and the condition local mapping waits on for it to grow.
  std::int64_t tracker_ns_ PKSLAM_GUARDED_BY(mutex_) = std::numeric_limits<std::int64_t>::min();
  ConditionVariable paced_;
  int idle_waiters_ PKSLAM_GUARDED_BY(mutex_) = 0;  // threads in WaitUntilIdle
  // Seconds on the emulation clock: priced work, the mapping thread's CPU time, or wall time.
  double LiveClockSeconds() const PKSLAM_REQUIRES(mutex_);
  bool finish_requested_ PKSLAM_GUARDED_BY(mutex_) = false;
  bool stop_requested_ PKSLAM_GUARDED_BY(mutex_) = false;
  bool stopped_ PKSLAM_GUARDED_BY(mutex_) = false;
  bool reset_requested_ PKSLAM_GUARDED_BY(mutex_) = false;
  LocalMappingStats stats_ PKSLAM_GUARDED_BY(mutex_);

  std::atomic<bool> accept_keyframes_{true};
  std::atomic<bool> abort_ba_{false};

  // Owned by the mapping thread: points created recently, checked by CullRecentPoints.
  RecentPoints recent_points_;

  // Online calibration's schedule and thread (mapping/online_calibrator.h), driven by the
  // mapping thread; Finish and the reset stop it.
  OnlineCalibrator calibrator_;
  // The IMU initialisation stages and gravity refinement (mapping/inertial_stages.h), driven
  // by the mapping thread.
  InertialStages inertial_stages_;

  std::thread thread_;
};

}  // namespace pkslam
