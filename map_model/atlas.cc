#include "map_model/atlas.h"

#include <algorithm>

#include "core/util/error.h"
#include "map_model/map_editor.h"

namespace pkslam {

Atlas::Atlas() { AddMap(); }

Atlas::~Atlas() {
  // Maps erase their keyframes from the database while clearing; the database goes last.
  for (auto& m : maps_) m->Clear();
  maps_.clear();
}

void Atlas::SetDatabase(std::unique_ptr<KeyFrameDatabase> database) {
  database_ = std::move(database);
  for (auto& m : maps_) m->set_database(database_.get());
}

void Atlas::RequireWriteLock(const MapWriteLock& lock, const char* operation) const {
  PKSLAM_CHECK(lock.Holds(*this), "Atlas::{} without the Atlas's write lock", operation);
}

Map* Atlas::CreateNewMap(const MapWriteLock& lock) {
  RequireWriteLock(lock, "CreateNewMap");
  return AddMap();
}

Map* Atlas::AddMap() {
  maps_.push_back(std::make_unique<Map>(next_map_id_++));
  current_ = maps_.back().get();
  current_->set_database(database_.get());
  return current_;
}

void Atlas::SetCurrentMap(const MapWriteLock& lock, Map* map) {
  RequireWriteLock(lock, "SetCurrentMap");
  current_ = map;
}

void Atlas::SetCalibration(const MapWriteLock& lock, RigCalibration calibration, RigSetup setup) {
  RequireWriteLock(lock, "SetCalibration");
  calibration_ = std::move(calibration);
  rig_setup_ = std::move(setup);
  calibration_version_.fetch_add(1);
}

void Atlas::RemoveMap(const MapWriteLock& lock, const Map* map) {
  RequireWriteLock(lock, "RemoveMap");
  std::erase_if(maps_, [map](const std::unique_ptr<Map>& m) { return m.get() == map; });
  if (current_ == map) current_ = maps_.empty() ? nullptr : maps_.back().get();
}

void Atlas::ResetCurrentMap(const MapWriteLock& lock) {
  RequireWriteLock(lock, "ResetCurrentMap");
  if (current_ != nullptr) current_->Clear();
}

std::vector<Map*> Atlas::maps() const {
  std::vector<Map*> out;
  out.reserve(maps_.size());
  for (const auto& m : maps_) out.push_back(m.get());
  return out;
}

MapEditTable Atlas::EditStats() const {
  MutexLock lock(edit_stats_mutex_);
  return edit_stats_;
}

void Atlas::RecordEdit(MapEdit edit, double held_s) const {
  MutexLock lock(edit_stats_mutex_);
  MapEditStats& s = edit_stats_[static_cast<std::size_t>(edit)];
  ++s.holds;
  s.total_s += held_s;
  s.max_s = std::max(s.max_s, held_s);
}

Map* Atlas::FindMap(MapId id) const {
  for (const auto& m : maps_) {
    if (m->id() == id) return m.get();
  }
  return nullptr;
}

}  // namespace pkslam
