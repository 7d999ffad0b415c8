// The one door to the map model (OpenVINS's StateHelper idea): the Atlas's reader/writer lock
// is private to it, and only MapEditor::Write takes it exclusively, naming the kind of change
// (MapEdit). Readers take it shared through MapReader. Every exclusive hold is counted and
// timed per kind (Atlas::EditStats: how long each kind of change keeps the other threads out),
// which is what a study of the threads' contention needs.
//
// Who writes what (threads as ORB-SLAM3's):
//   tracking       kInitialise, kInsertKeyFrame, kReset
//   local mapping  kProcessKeyFrame, kCullPoints, kCreatePoints, kFuse, kCullKeyFrames,
//                  kApplyBundle, kApplyInertialBundle, kInertialInitialisation, kCalibration
//                  (kCalibration also from its calibration thread)
//   loop closing   kLoopCorrection, kMergeMaps, kGlobalBundle
//   system         kLoadMap, kCalibration (the file's calibration before the first frame)
//   tests          kFixture (maps built by hand)
#pragma once

#include <chrono>
#include <mutex>
#include <shared_mutex>
#include <string_view>

#include "map_model/atlas.h"

namespace pkslam {

// The exclusive lock on the Atlas, held for one kind of change. Movable, not copyable; may be
// released early (unlock) and taken again (lock) like std::unique_lock. Each hold is recorded
// in the Atlas's edit statistics when it ends.
class MapWriteLock {
 public:
  MapWriteLock(MapWriteLock&& other) noexcept = default;
  MapWriteLock& operator=(MapWriteLock&& other) = delete;
  MapWriteLock(const MapWriteLock&) = delete;
  MapWriteLock& operator=(const MapWriteLock&) = delete;
  ~MapWriteLock();

  void unlock();
  void lock();
  bool owns_lock() const { return lock_.owns_lock(); }
  // Whether this lock is held on `atlas` (a write lock of another Atlas proves nothing).
  bool Holds(const Atlas& atlas) const { return atlas_ == &atlas && lock_.owns_lock(); }
  MapEdit edit() const { return edit_; }

 private:
  friend class MapEditor;
  MapWriteLock(const Atlas* atlas, MapEdit edit, std::defer_lock_t);

  const Atlas* atlas_;
  MapEdit edit_;
  std::unique_lock<std::shared_mutex> lock_;
  std::chrono::steady_clock::time_point since_;
};

// Throws Error naming `operation` unless `lock` is held: the first line of every map change
// that takes the lock as a parameter (a deferred or released lock proves nothing).
void RequireWriteLock(const MapWriteLock& lock, std::string_view operation);

class MapEditor {
 public:
  explicit MapEditor(Atlas* atlas);
  // Blocks until no reader or writer holds the Atlas; the map model may then be changed.
  [[nodiscard]] MapWriteLock Write(MapEdit edit) const;
  // As Write, but not locked yet (std::defer_lock): call lock() on it.
  [[nodiscard]] MapWriteLock WriteLater(MapEdit edit) const;

 private:
  Atlas* atlas_;
};

// The shared lock on the Atlas, for readers. Movable, not copyable; may be released early
// (unlock) and taken again (lock) like std::shared_lock.
class MapReadLock {
 public:
  MapReadLock() = default;  // holds nothing (a member locked later)
  MapReadLock(MapReadLock&& other) noexcept = default;
  MapReadLock& operator=(MapReadLock&& other) noexcept = default;
  MapReadLock(const MapReadLock&) = delete;
  MapReadLock& operator=(const MapReadLock&) = delete;

  void unlock() { lock_.unlock(); }
  void lock() { lock_.lock(); }
  bool owns_lock() const { return lock_.owns_lock(); }
  bool Holds(const Atlas& atlas) const { return atlas_ == &atlas && lock_.owns_lock(); }

 private:
  friend class MapReader;
  explicit MapReadLock(const Atlas* atlas);

  const Atlas* atlas_ = nullptr;
  std::shared_lock<std::shared_mutex> lock_;
};

class MapReader {
 public:
  explicit MapReader(const Atlas& atlas) : atlas_(&atlas) {}
  // Shared: any number of readers, no writer, while it is held.
  [[nodiscard]] MapReadLock Lock() const;

 private:
  const Atlas* atlas_;
};

// What a reader of the map model takes as a parameter: the proof that its caller holds the
// Atlas's lock, shared (MapReadLock) or exclusive (MapWriteLock); both convert to it. A view:
// it must not outlive the lock it was made from.
class MapLock {
 public:
  MapLock(const MapReadLock& lock) : read_(&lock) {}    // NOLINT(google-explicit-constructor)
  MapLock(const MapWriteLock& lock) : write_(&lock) {}  // NOLINT(google-explicit-constructor)
  bool owns_lock() const { return read_ != nullptr ? read_->owns_lock() : write_->owns_lock(); }

 private:
  const MapReadLock* read_ = nullptr;
  const MapWriteLock* write_ = nullptr;
};

// Throws Error naming `operation` unless `lock` is held (shared or exclusive).
void RequireMapLock(const MapLock& lock, std::string_view operation);

}  // namespace pkslam
