// Ordered prefetching of numbered items in a background thread (image decoding ahead of
// tracking: PNG decoding is about a third of the tracking thread's CPU time on EuRoC stereo).
//
// Prefetcher<T>(count, load, depth) calls load(0), load(1), ... load(count - 1) in its own
// thread, keeping at most `depth` loaded items waiting; Next() hands them out in order and
// returns std::nullopt after the last one. An exception thrown by load(i) is rethrown by the
// Next() call that would have returned item i (nothing after it is loaded).
//
// Threads: one consumer thread calls Next(); the loader thread is owned by the object and
// joined by the destructor (which stops loading early). mutex_ guards queue_, error_,
// handed_out_ and stop_ (PKSLAM_GUARDED_BY, core/util/annotated_mutex.h).
#pragma once

#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <optional>
#include <thread>
#include <utility>

#include "core/util/annotated_mutex.h"
#include "core/util/error.h"

namespace pkslam {

template <typename T>
class Prefetcher {
 public:
  Prefetcher(std::size_t count, std::function<T(std::size_t)> load, std::size_t depth)
      : count_(count), load_(std::move(load)), depth_(depth) {
    PKSLAM_CHECK(depth_ >= 1, "prefetch depth must be at least 1");
    thread_ = std::thread([this] { Run(); });
  }
  ~Prefetcher() {
    {
      MutexLock lock(mutex_);
      stop_ = true;
    }
    space_.notify_all();
    thread_.join();
  }
  Prefetcher(const Prefetcher&) = delete;
  Prefetcher& operator=(const Prefetcher&) = delete;

  // The next item in order, waiting for it if needed; std::nullopt after the last.
  std::optional<T> Next() {
    MutexLock lock(mutex_);
    if (handed_out_ >= count_) return std::nullopt;
    while (queue_.empty() && error_ == nullptr) ready_.wait(lock);
    if (queue_.empty()) {
      handed_out_ = count_;  // nothing follows a failed item
      std::rethrow_exception(error_);
    }
    T item = std::move(queue_.front());
    queue_.pop_front();
    ++handed_out_;
    lock.unlock();
    space_.notify_all();
    return item;
  }

 private:
  void Run() {
    for (std::size_t i = 0; i < count_; ++i) {
      {
        MutexLock lock(mutex_);
        while (!stop_ && queue_.size() >= depth_) space_.wait(lock);
        if (stop_) return;
      }
      try {
        T item = load_(i);
        MutexLock lock(mutex_);
        queue_.push_back(std::move(item));
      } catch (...) {
        MutexLock lock(mutex_);
        error_ = std::current_exception();
        ready_.notify_all();
        return;
      }
      ready_.notify_all();
    }
  }

  const std::size_t count_;
  const std::function<T(std::size_t)> load_;
  const std::size_t depth_;
  Mutex mutex_;
  ConditionVariable ready_;  // an item or an error arrived
  ConditionVariable space_;  // an item was taken, or stop
  std::deque<T> queue_ PKSLAM_GUARDED_BY(mutex_);
  std::exception_ptr error_ PKSLAM_GUARDED_BY(mutex_);
  std::size_t handed_out_ PKSLAM_GUARDED_BY(mutex_) = 0;  // consumer side
  bool stop_ PKSLAM_GUARDED_BY(mutex_) = false;
  std::thread thread_;
};

}  // namespace pkslam
