// LocalMapper: the thread, its queue and the stop/reset handshakes.
#include "mapping/local_mapper.h"

#include "core/util/error.h"

namespace pkslam {

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
  ba.Check();
  inertial.Check();
}

LocalMapper::LocalMapper(Atlas* atlas, std::shared_ptr<const CameraRig> rig,
                         LocalMappingOptions options)
    : atlas_(atlas), rig_(std::move(rig)), options_(options) {
  options_.Check();
}

LocalMapper::~LocalMapper() { Finish(); }

void LocalMapper::SetKeyFrameConsumer(std::function<void(const KeyFramePtr&)> consumer) {
  consumer_ = std::move(consumer);
}

void LocalMapper::Start() {
  PKSLAM_CHECK(!thread_.joinable(), "local mapping already started");
  thread_ = std::thread([this] { Run(); });
}

void LocalMapper::Finish() {
  {
    std::lock_guard lock(mutex_);
    finish_requested_ = true;
    stop_requested_ = false;
  }
  wake_.notify_all();
  if (thread_.joinable()) {
    thread_.join();
  } else {
    // Never started: drain inline so every keyframe still gets processed.
    while (HasQueued()) ProcessNext();
  }
}

void LocalMapper::InsertKeyFrame(const KeyFramePtr& kf) {
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(kf);
    abort_ba_.store(true);  // a running BA yields to the newer keyframe
  }
  wake_.notify_all();
}

bool LocalMapper::HasQueued() const {
  std::lock_guard lock(mutex_);
  return !queue_.empty();
}

int LocalMapper::QueueSize() const {
  std::lock_guard lock(mutex_);
  return static_cast<int>(queue_.size());
}

bool LocalMapper::IsStoppedOrStopRequested() const {
  std::lock_guard lock(mutex_);
  return stop_requested_ || stopped_;
}

void LocalMapper::WaitUntilIdle() {
  if (!thread_.joinable()) {
    while (HasQueued()) ProcessNext();
    return;
  }
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [this] { return (queue_.empty() && !busy_) || stopped_ || finish_requested_; });
}

void LocalMapper::ResetQueue() {
  if (!thread_.joinable()) {
    std::lock_guard lock(mutex_);
    queue_.clear();
    recent_points_.clear();
    return;
  }
  std::unique_lock lock(mutex_);
  reset_requested_ = true;
  wake_.notify_all();
  idle_.wait(lock, [this] { return !reset_requested_ || finish_requested_; });
}

void LocalMapper::RequestStop() {
  {
    std::lock_guard lock(mutex_);
    stop_requested_ = true;
  }
  abort_ba_.store(true);
  wake_.notify_all();
}

bool LocalMapper::IsStopped() const {
  std::lock_guard lock(mutex_);
  return stopped_;
}

void LocalMapper::Release() {
  {
    std::lock_guard lock(mutex_);
    stop_requested_ = false;
  }
  wake_.notify_all();
}

LocalMappingStats LocalMapper::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

void LocalMapper::Run() {
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, [this] {
      return finish_requested_ || reset_requested_ || stop_requested_ || !queue_.empty();
    });
    if (reset_requested_) {
      queue_.clear();
      recent_points_.clear();
      reset_requested_ = false;
      idle_.notify_all();
      continue;
    }
    if (stop_requested_ && !finish_requested_) {
      stopped_ = true;
      accept_keyframes_.store(false);
      idle_.notify_all();
      wake_.wait(lock, [this] { return !stop_requested_ || finish_requested_; });
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
    lock.unlock();
    ProcessNext();
    lock.lock();
    busy_ = false;
    if (queue_.empty()) accept_keyframes_.store(true);
    idle_.notify_all();
  }
  accept_keyframes_.store(true);
  idle_.notify_all();
}

}  // namespace pkslam
