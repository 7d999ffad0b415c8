#include "map_model/map_editor.h"

#include "core/util/error.h"

namespace pkslam {

std::string_view MapEditName(MapEdit edit) {
  switch (edit) {
    case MapEdit::kInitialise:
      return "initialise";
    case MapEdit::kInsertKeyFrame:
      return "insert_keyframe";
    case MapEdit::kReset:
      return "reset";
    case MapEdit::kProcessKeyFrame:
      return "process_keyframe";
    case MapEdit::kCullPoints:
      return "cull_points";
    case MapEdit::kCreatePoints:
      return "create_points";
    case MapEdit::kFuse:
      return "fuse";
    case MapEdit::kCullKeyFrames:
      return "cull_keyframes";
    case MapEdit::kApplyBundle:
      return "apply_bundle";
    case MapEdit::kApplyInertialBundle:
      return "apply_inertial_bundle";
    case MapEdit::kInertialInitialisation:
      return "inertial_initialisation";
    case MapEdit::kCalibration:
      return "calibration";
    case MapEdit::kLoopCorrection:
      return "loop_correction";
    case MapEdit::kMergeMaps:
      return "merge_maps";
    case MapEdit::kGlobalBundle:
      return "global_bundle";
    case MapEdit::kLoadMap:
      return "load_map";
    case MapEdit::kFixture:
      return "fixture";
  }
  return "unknown";
}

MapWriteLock::MapWriteLock(const Atlas* atlas, MapEdit edit, std::defer_lock_t)
    : atlas_(atlas), edit_(edit), lock_(atlas->mutex_, std::defer_lock) {}

MapWriteLock::~MapWriteLock() {
  if (lock_.owns_lock()) unlock();
}

void MapWriteLock::lock() {
  lock_.lock();
  since_ = std::chrono::steady_clock::now();
}

void MapWriteLock::unlock() {
  const double held_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - since_).count();
  lock_.unlock();
  atlas_->RecordEdit(edit_, held_s);
}

MapEditor::MapEditor(Atlas* atlas) : atlas_(atlas) {
  PKSLAM_CHECK(atlas_ != nullptr, "MapEditor without an Atlas");
}

void RequireWriteLock(const MapWriteLock& lock, std::string_view operation) {
  PKSLAM_CHECK(lock.owns_lock(), "{} without the Atlas's write lock", operation);
}

MapWriteLock MapEditor::Write(MapEdit edit) const {
  MapWriteLock lock(atlas_, edit, std::defer_lock);
  lock.lock();
  return lock;
}

MapWriteLock MapEditor::WriteLater(MapEdit edit) const {
  return MapWriteLock(atlas_, edit, std::defer_lock);
}

MapReadLock::MapReadLock(const Atlas* atlas) : atlas_(atlas), lock_(atlas->mutex_) {}

MapReadLock MapReader::Lock() const { return MapReadLock(atlas_); }

void RequireMapLock(const MapLock& lock, std::string_view operation) {
  PKSLAM_CHECK(lock.owns_lock(), "{} without the Atlas's lock", operation);
}

}  // namespace pkslam
