// A mutex that Clang's thread-safety analysis can follow (-Wthread-safety; the attributes
// compile to nothing under GCC, which builds pkslam). libstdc++'s std::mutex carries no
// capability attributes, so members guarded by a plain std::mutex cannot be checked: a class
// whose own members are guarded by its mutex uses Mutex, MutexLock and ConditionVariable
// instead and marks the members PKSLAM_GUARDED_BY(mutex_). CTest `layering.thread_safety`
// (tests/layering/check_thread_safety.py) compiles those classes with Clang and the analysis on.
//
// Not annotated: the Atlas lock (map_model/map_editor.h). It guards objects outside the Atlas
// (every Map, KeyFrame and MapPoint), which the analysis cannot attach to a mutex member.
#pragma once

#include <condition_variable>
#include <mutex>

#if defined(__clang__)
#define PKSLAM_THREAD_ANNOTATION(x) __attribute__((x))
#else
#define PKSLAM_THREAD_ANNOTATION(x)
#endif

#define PKSLAM_CAPABILITY(x) PKSLAM_THREAD_ANNOTATION(capability(x))
#define PKSLAM_SCOPED_CAPABILITY PKSLAM_THREAD_ANNOTATION(scoped_lockable)
#define PKSLAM_GUARDED_BY(x) PKSLAM_THREAD_ANNOTATION(guarded_by(x))
#define PKSLAM_REQUIRES(...) PKSLAM_THREAD_ANNOTATION(requires_capability(__VA_ARGS__))
#define PKSLAM_ACQUIRE(...) PKSLAM_THREAD_ANNOTATION(acquire_capability(__VA_ARGS__))
#define PKSLAM_RELEASE(...) PKSLAM_THREAD_ANNOTATION(release_capability(__VA_ARGS__))
#define PKSLAM_EXCLUDES(...) PKSLAM_THREAD_ANNOTATION(locks_excluded(__VA_ARGS__))

namespace pkslam {

class PKSLAM_CAPABILITY("mutex") Mutex {
 public:
  void lock() PKSLAM_ACQUIRE() { mutex_.lock(); }
  void unlock() PKSLAM_RELEASE() { mutex_.unlock(); }

 private:
  std::mutex mutex_;
};

// Holds a Mutex from construction to destruction, except between unlock() and lock(). It is
// BasicLockable, so a ConditionVariable waits on it; the analysis sees the mutex held across
// a wait, which is true where it matters (on entry and on return). Wait in a loop around the
// condition (while (!ready) cv.wait(lock);): a predicate lambda is analysed on its own, without
// the lock.
class PKSLAM_SCOPED_CAPABILITY MutexLock {
 public:
  explicit MutexLock(Mutex& mutex) PKSLAM_ACQUIRE(mutex) : mutex_(mutex) { mutex_.lock(); }
  ~MutexLock() PKSLAM_RELEASE() {
    if (held_) mutex_.unlock();
  }
  MutexLock(const MutexLock&) = delete;
  MutexLock& operator=(const MutexLock&) = delete;

  void lock() PKSLAM_ACQUIRE() {
    mutex_.lock();
    held_ = true;
  }
  void unlock() PKSLAM_RELEASE() {
    mutex_.unlock();
    held_ = false;
  }

 private:
  Mutex& mutex_;
  bool held_ = true;
};

// Waits on a MutexLock (std::condition_variable only takes std::unique_lock<std::mutex>).
using ConditionVariable = std::condition_variable_any;

}  // namespace pkslam
