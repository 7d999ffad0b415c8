// LocalMapper: the thread, its queue and the stop/reset handshakes.
#include "mapping/local_mapper.h"

#include <algorithm>

#include "core/util/cpu_time.h"
#include "core/util/error.h"
#include "core/util/wall_time.h"
#include "map_model/keyframe.h"

namespace pkslam {

// Fitted by evaluation/studies/coupling/fit_work_model.py to 1568 keyframes of six runs
// (60 s realistic replays of V1_02, V1_03 and V2_02, mono-inertial and stereo-inertial, CPU
// clock, 2 cores; 2026-11-28): a keyframe 0.66 ms, a fused projection 0.14 us, a scalar solver
// residual per iteration 0.29 us; triangulation keypoints got no weight of their own (they
// grow with the keyframe count). Totals per run: 0.96-1.02x the measured CPU seconds
// mono-inertial, 0.83-0.88x stereo-inertial; median error per keyframe 9-15%.
const WorkModel kReferenceWork{{6.593e-4, 0.0, 1.351e-7, 2.854e-7}};

std::optional<LiveClock> ParseLiveClock(std::string_view name) {
  if (name == "work") return LiveClock::kWork;
  if (name == "cpu") return LiveClock::kCpu;
  if (name == "wall") return LiveClock::kWall;
  return std::nullopt;
}

void LocalMappingOptions::Check() const {
  PKSLAM_CHECK_OPTION(triangulation_neighbours_stereo > 0 && triangulation_neighbours_mono > 0,
                      "LocalMapping.triangulation_neighbours", "{} / {}",
                      triangulation_neighbours_stereo, triangulation_neighbours_mono);
  PKSLAM_CHECK_OPTION(culling_redundancy > 0 && culling_redundancy <= 1,
                      "LocalMapping.culling_redundancy", "{}", culling_redundancy);
  PKSLAM_CHECK_OPTION(culling_observers > 0, "LocalMapping.culling_observers", "{}",
                      culling_observers);
  PKSLAM_CHECK_OPTION(min_found_ratio >= 0 && min_found_ratio < 1, "LocalMapping.min_found_ratio",
                      "{}", min_found_ratio);
  PKSLAM_CHECK_OPTION(max_queued_keyframes >= 2, "LocalMapping.max_queued_keyframes",
                      "{} (a map's initialisation inserts two keyframes)", max_queued_keyframes);
  ba.Check();
  inertial.Check();
  calibration.Check();
}

LocalMapper::LocalMapper(Atlas* atlas, std::shared_ptr<const CameraRig> rig,
                         LocalMappingOptions options)
    : atlas_(atlas),
      rig_(std::move(rig)),
      options_(options),
      calibrator_(atlas, rig_->sensor, options_.calibration, options_.ba.num_threads),
      inertial_stages_(
          atlas, rig_->sensor, options_.inertial, options_.ba.num_threads,
          InertialStageHooks{[this] { return HasQueued(); },
                             [this] { return calibrator_.Running(); }, &abort_ba_, &work_}) {
  options_.Check();
}

LocalMapper::~LocalMapper() { Finish(); }

void LocalMapper::SetKeyFrameConsumer(std::function<void(const KeyFramePtr&)> consumer) {
  consumer_ = std::move(consumer);
}

void LocalMapper::SetCalibrationPrior(RigCalibration file, RigShape shape) {
  calibrator_.SetPrior(std::move(file), std::move(shape));
}

void LocalMapper::Start() {
  PKSLAM_CHECK(!thread_.joinable(), "local mapping already started");
  {
    MutexLock lock(mutex_);
    running_ = true;
  }
  thread_ = std::thread([this] { Run(); });
}

void LocalMapper::Finish() {
  {
    MutexLock lock(mutex_);
    finish_requested_ = true;
    stop_requested_ = false;
  }
  wake_.notify_all();
  paced_.notify_all();
  if (thread_.joinable()) {
    thread_.join();
    calibrator_.Stop();  // the run's final adjustment follows (SlamSystem)
  } else {
    // Never started: drain inline so every keyframe still gets processed.
    while (HasQueued()) ProcessNext();
  }
}

void LocalMapper::InsertKeyFrame(const KeyFramePtr& kf) {
  if (!thread_.joinable()) {
    // No thread (tests, lock-step callers that drain it): the caller makes the room.
    while (QueueSize() >= options_.max_queued_keyframes) ProcessNext();
  }
  {
    MutexLock lock(mutex_);
    // Backpressure: tracking declines keyframes while the queue is full (QueueFull), so only a
    // keyframe it cannot decline waits here, until local mapping takes one (Run notifies idle_
    // as it does), or a finish or reset makes the wait moot.
    while (running_ && static_cast<int>(queue_.size()) >= options_.max_queued_keyframes &&
           !finish_requested_ && !reset_requested_) {
      idle_.wait(lock);
    }
    queue_.push_back(kf);
    stats_.max_queued_keyframes =
        std::max(stats_.max_queued_keyframes, static_cast<int>(queue_.size()));
    abort_ba_.store(true);  // a running BA yields to the newer keyframe
  }
  wake_.notify_all();
}

bool LocalMapper::HasQueued() const {
  MutexLock lock(mutex_);
  return !queue_.empty();
}

int LocalMapper::QueueSize() const {
  MutexLock lock(mutex_);
  return static_cast<int>(queue_.size());
}

bool LocalMapper::QueueFull() const {
  MutexLock lock(mutex_);
  return static_cast<int>(queue_.size()) >= options_.max_queued_keyframes;
}

bool LocalMapper::IsStoppedOrStopRequested() const {
  MutexLock lock(mutex_);
  return stop_requested_ || stopped_;
}

void LocalMapper::WaitUntilIdle() {
  if (!thread_.joinable()) {
    while (HasQueued()) ProcessNext();
    return;
  }
  MutexLock lock(mutex_);
  // Whoever waits for idle sends no more frames meanwhile: paced work must not wait for them.
  ++idle_waiters_;
  paced_.notify_all();
  while (!((queue_.empty() && !busy_) || stopped_ || finish_requested_)) idle_.wait(lock);
  --idle_waiters_;
}

void LocalMapper::EmulateLive(bool on, double pace, LiveClock clock) {
  PKSLAM_CHECK(!thread_.joinable(), "live emulation is set before Start()");
  emulate_live_ = on;
  live_pace_ = pace;
  live_clock_ = clock;
  CalibrationPacing calibration;
  calibration.paced = Paced();
  if (Paced()) {
    work_.SetPacer([this] { PaceToTracker(); });
    calibration.position = [this] {
      MutexLock lock(mutex_);
      return LiveDataPosition{LiveReachedNs(),
                              stop_requested_ || finish_requested_ || reset_requested_};
    };
    calibration.data_ns = [this](const WorkCounts& work) {
      return DataNs(kReferenceWork.Seconds(work));
    };
  } else {
    work_.SetPacer(nullptr);
  }
  calibrator_.SetPacing(std::move(calibration));
}

void LocalMapper::NoteFrameTime(std::int64_t t_ns) {
  if (!Paced()) return;
  {
    MutexLock lock(mutex_);
    tracker_ns_ = std::max(tracker_ns_, t_ns);
  }
  paced_.notify_all();
}

std::int64_t LocalMapper::LiveReachedNs() const {
  return live_job_start_ns_ + DataNs(LiveClockSeconds() - live_job_clock_start_);
}

void LocalMapper::PaceToTracker() {
  if (!Paced() || !thread_.joinable() || std::this_thread::get_id() != thread_.get_id()) return;
  MutexLock lock(mutex_);
  const std::int64_t reached = LiveReachedNs();
  idle_.notify_all();  // tracking may be waiting for the work to reach its frame's time
  while (tracker_ns_ < reached && idle_waiters_ == 0 && !stop_requested_ && !finish_requested_ &&
         !reset_requested_) {
    paced_.wait(lock);
  }
}

bool LocalMapper::AcceptsKeyFramesAt(std::int64_t t_ns) {
  if (!emulate_live_ || !thread_.joinable()) return AcceptsKeyFrames();
  const auto wait_start = std::chrono::steady_clock::now();
  MutexLock lock(mutex_);
  if (Paced() && t_ns > tracker_ns_) {
    // The caller is at this frame (NoteFrameTime's contract): paced work must not wait for it.
    tracker_ns_ = t_ns;
    paced_.notify_all();
  }
  while (true) {
    if (stopped_ || stop_requested_ || finish_requested_ || reset_requested_) break;
    if (!busy_ && queue_.empty()) break;
    if (busy_) {
      // Where the current keyframe's processing has got to on the data clock, at least.
      const std::int64_t reached = LiveReachedNs();
      if (reached >= t_ns) break;  // still busy at t_ns, for certain
      // The CPU and wall clocks cannot run faster than real time: wait until the job could
      // have reached t_ns. Work is counted, and PaceToTracker notifies after each step and
      // solver iteration; the short timeout only bounds a missed case.
      const double wait_s = live_clock_ == LiveClock::kWork
                                ? 0.002
                                : static_cast<double>(t_ns - reached) * 1e-9 / live_pace_;
      idle_.wait_for(lock, std::chrono::duration<double>(wait_s));
    } else {
      idle_.wait(lock);  // a queued keyframe is about to be taken
    }
  }
  stats_.live_wait_ms += WallMsSince(wait_start);
  return !busy_ && queue_.empty() && !stopped_ && !stop_requested_ && live_free_ns_ <= t_ns;
}

double LocalMapper::LiveClockSeconds() const {
  if (live_clock_ == LiveClock::kWork) return kReferenceWork.Seconds(work_.Snapshot());
  if (live_clock_ == LiveClock::kCpu && mapping_cpu_clock_) {
    return ClockSeconds(*mapping_cpu_clock_);
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::int64_t LocalMapper::DataNs(double work_s) const {
  return static_cast<std::int64_t>(work_s * live_pace_ * 1e9);
}

void LocalMapper::ResetQueue() {
  if (!thread_.joinable()) {
    MutexLock lock(mutex_);
    queue_.clear();
    recent_points_.Clear();
    return;
  }
  MutexLock lock(mutex_);
  reset_requested_ = true;
  wake_.notify_all();
  paced_.notify_all();
  idle_.notify_all();  // an inserter waiting for room: the queue is about to be dropped
  while (reset_requested_ && !finish_requested_) idle_.wait(lock);
}

void LocalMapper::RequestStop() {
  {
    MutexLock lock(mutex_);
    stop_requested_ = true;
  }
  abort_ba_.store(true);
  // A merge would discard the adjustment's result. A paced one runs on: where it stopped would
  // depend on this machine's speed.
  if (!Paced()) calibrator_.Interrupt();
  wake_.notify_all();
  paced_.notify_all();
}

bool LocalMapper::IsStopped() const {
  MutexLock lock(mutex_);
  return stopped_;
}

void LocalMapper::Release() {
  {
    MutexLock lock(mutex_);
    stop_requested_ = false;
  }
  wake_.notify_all();
}

LocalMappingStats LocalMapper::stats() const {
  LocalMappingStats stats;
  {
    MutexLock lock(mutex_);
    stats = stats_;
  }
  stats.calibration_refinements = calibrator_.history();
  InertialStagesStats inertial = inertial_stages_.stats();
  stats.imu_stages = std::move(inertial.imu_stages);
  stats.gravity_refinements = std::move(inertial.gravity_refinements);
  stats.gravity_refinements_dropped = inertial.gravity_refinements_dropped;
  return stats;
}

void LocalMapper::Run() {
  MutexLock lock(mutex_);
  mapping_cpu_clock_ = CallingThreadCpuClock();
  while (true) {
    while (!(finish_requested_ || reset_requested_ || stop_requested_ || !queue_.empty())) {
      wake_.wait(lock);
    }
    if (reset_requested_) {
      lock.unlock();
      calibrator_.Stop();  // its map is about to go
      lock.lock();
      live_free_ns_ = std::numeric_limits<std::int64_t>::min();
      queue_.clear();
      recent_points_.Clear();
      reset_requested_ = false;
      idle_.notify_all();
      continue;
    }
    if (stop_requested_ && !finish_requested_) {
      stopped_ = true;
      accept_keyframes_.store(false);
      idle_.notify_all();
      while (stop_requested_ && !finish_requested_) wake_.wait(lock);
      stopped_ = false;
      accept_keyframes_.store(true);
      continue;
    }
    if (queue_.empty()) {
      if (finish_requested_) break;
      continue;
    }
    busy_ = true;
    accept_keyframes_.store(false);
    live_job_start_ns_ = std::max(queue_.front()->t_ns(), live_free_ns_);
    live_job_clock_start_ = LiveClockSeconds();
    idle_.notify_all();  // AcceptsKeyFramesAt waits for a queued keyframe to be taken
    lock.unlock();
    ProcessNext();
    lock.lock();
    live_free_ns_ = LiveReachedNs();
    busy_ = false;
    if (queue_.empty()) accept_keyframes_.store(true);
    idle_.notify_all();
  }
  running_ = false;
  accept_keyframes_.store(true);
  idle_.notify_all();
}

}  // namespace pkslam
