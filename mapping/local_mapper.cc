// LocalMapper: the thread, its queue, live emulation's pacing and the stop/reset handshakes;
// the keyframe's own steps are mapping/keyframe_steps.h.
#include "mapping/local_mapper.h"

#include <algorithm>
#include <chrono>

#include "core/util/cpu_time.h"
#include "core/util/error.h"
#include "core/util/wall_time.h"
#include "map_model/keyframe.h"

namespace pkslam {

LocalMapper::LocalMapper(Atlas* atlas, std::shared_ptr<const CameraRig> rig,
                         LocalMappingOptions options)
    : atlas_(atlas),
      rig_(std::move(rig)),
      options_(options),
      timeline_(live_, &work_),
      steps_(atlas, rig_, options_,
             KeyFrameStepHooks{
                 [this] { return HasQueued(); }, [this] { return IsStoppedOrStopRequested(); },
                 [this] { StepBoundary(); }, [this] { PaceToTracker(); }, &abort_ba_, &work_}),
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
  live_ = LiveEmulation{on, pace, clock};
  {
    MutexLock lock(mutex_);
    timeline_ = LiveTimeline(live_, &work_);
  }
  CalibrationPacing calibration;
  calibration.paced = Paced();
  if (Paced()) {
    work_.SetPacer([this] { PaceToTracker(); });
    calibration.position = [this] {
      MutexLock lock(mutex_);
      return LiveDataPosition{timeline_.ReachedNs(),
                              stop_requested_ || finish_requested_ || reset_requested_};
    };
    calibration.data_ns = [this](const WorkCounts& work) {
      return live_.DataNs(kReferenceWork.Seconds(work));
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
    timeline_.AdvanceTracker(t_ns);
  }
  paced_.notify_all();
}

void LocalMapper::PaceToTracker() {
  if (!Paced() || !thread_.joinable() || std::this_thread::get_id() != thread_.get_id()) return;
  MutexLock lock(mutex_);
  const std::int64_t reached = timeline_.ReachedNs();
  idle_.notify_all();  // tracking may be waiting for the work to reach its frame's time
  while (timeline_.TrackerBefore(reached) && idle_waiters_ == 0 && !stop_requested_ &&
         !finish_requested_ && !reset_requested_) {
    paced_.wait(lock);
  }
}

bool LocalMapper::AcceptsKeyFramesAt(std::int64_t t_ns) {
  if (!live_.on || !thread_.joinable()) return AcceptsKeyFrames();
  const auto wait_start = std::chrono::steady_clock::now();
  MutexLock lock(mutex_);
  // The caller is at this frame (NoteFrameTime's contract): paced work must not wait for it.
  if (Paced() && timeline_.AdvanceTracker(t_ns)) paced_.notify_all();
  while (true) {
    if (stopped_ || stop_requested_ || finish_requested_ || reset_requested_) break;
    if (!busy_ && queue_.empty()) break;
    if (busy_) {
      // Where the current keyframe's processing has got to on the data clock, at least.
      const std::int64_t reached = timeline_.ReachedNs();
      if (reached >= t_ns) break;  // still busy at t_ns, for certain
      // PaceToTracker notifies after each step and solver iteration.
      idle_.wait_for(lock, std::chrono::duration<double>(timeline_.RecheckSeconds(t_ns, reached)));
    } else {
      idle_.wait(lock);  // a queued keyframe is about to be taken
    }
  }
  stats_.live_wait_ms += WallMsSince(wait_start);
  return !busy_ && queue_.empty() && !stopped_ && !stop_requested_ && timeline_.FreeBy(t_ns);
}

void LocalMapper::ResetQueue() {
  if (!thread_.joinable()) {
    MutexLock lock(mutex_);
    queue_.clear();
    steps_.ForgetRecentPoints();
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

void LocalMapper::ProcessNext() {
  KeyFramePtr kf;
  {
    MutexLock lock(mutex_);
    if (queue_.empty()) return;
    kf = queue_.front();
    queue_.pop_front();
  }
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = ThreadCpuSeconds();
  const WorkCounts work_start = work_.Snapshot();
  work_.Add(WorkKind::kKeyFrame, 1);
  abort_ba_.store(false);
  const KeyFrameStepReport steps = steps_.Run(kf);
  // A step boundary before each whole-map step too: it changes the map at a data time tracking
  // has reached, as does applying an adjustment solved in the calibration thread.
  StepBoundary();
  if (IsInertial(rig_->sensor) && !IsStoppedOrStopRequested()) inertial_stages_.Step(kf);
  StepBoundary();
  if (options_.calibration.enabled && !IsStoppedOrStopRequested()) {
    calibrator_.Step(kf, HasQueued(), !options_.calibration.own_thread || !thread_.joinable(),
                     &abort_ba_, &work_);
  }
  StepBoundary();
  {
    MutexLock lock(mutex_);
    stats_.points_culled += steps.points_culled;
    stats_.points_created += steps.points_created;
    stats_.keyframes_culled += steps.keyframes_culled;
    if (steps.ba_aborted) ++stats_.ba_aborted;
    if (steps.inertial_ba) {
      ++(steps.inertial_ba_with_prior ? stats_.inertial_ba_with_prior
                                      : stats_.inertial_ba_fixed_anchor);
    }
    stats_.keyframe_ms.push_back(WallMsSince(start));
    stats_.ba_ms.push_back(steps.ba_ms);
    stats_.keyframe_cpu_ms.push_back(1e3 * (ThreadCpuSeconds() - cpu_start));
    stats_.ba_cpu_ms.push_back(steps.ba_cpu_ms);
    stats_.keyframe_work.push_back(work_.Snapshot() - work_start);
  }
  if (consumer_) consumer_(kf);
}

void LocalMapper::Run() {
  MutexLock lock(mutex_);
  timeline_.SetCpuClock(CallingThreadCpuClock());
  while (true) {
    while (!(finish_requested_ || reset_requested_ || stop_requested_ || !queue_.empty())) {
      wake_.wait(lock);
    }
    if (reset_requested_) {
      lock.unlock();
      calibrator_.Stop();  // its map is about to go
      lock.lock();
      timeline_.Reset();
      queue_.clear();
      steps_.ForgetRecentPoints();
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
    timeline_.StartJob(queue_.front()->t_ns());
    idle_.notify_all();  // AcceptsKeyFramesAt waits for a queued keyframe to be taken
    lock.unlock();
    ProcessNext();
    lock.lock();
    timeline_.EndJob();
    busy_ = false;
    if (queue_.empty()) accept_keyframes_.store(true);
    idle_.notify_all();
  }
  running_ = false;
  accept_keyframes_.store(true);
  idle_.notify_all();
}

}  // namespace pkslam
