// The Atlas: all maps of a session, the current (active) map, the id counters and the mutex
// that guards the whole map model. The mutex is private: readers lock it through MapReader,
// writers through MapEditor (map_editor.h), the only code that takes it exclusively (see
// docs/architecture.md for the locking rules).
#pragma once

#include <atomic>
#include <memory>
#include <shared_mutex>
#include <vector>

#include "core/sensor/rig_calibration.h"
#include "core/util/annotated_mutex.h"
#include "map_model/keyframe_database.h"
#include "map_model/map.h"
#include "map_model/map_edit.h"
#include "map_model/map_ids.h"

namespace pkslam {

class MapWriteLock;

class Atlas {
 public:
  Atlas();
  ~Atlas();
  Atlas(const Atlas&) = delete;
  Atlas& operator=(const Atlas&) = delete;

  // Changes of the set of maps, each under this Atlas's write lock (checked: Error without it).
  // A new empty map, which becomes current.
  Map* CreateNewMap(const MapWriteLock& lock);
  void SetCurrentMap(const MapWriteLock& lock, Map* map);
  // Removes an (empty or merged) map.
  void RemoveMap(const MapWriteLock& lock, const Map* map);
  // Clears the current map's content (a reset) keeping the map object.
  void ResetCurrentMap(const MapWriteLock& lock);

  // Requires at least the shared lock.
  Map* current_map() const { return current_; }
  std::vector<Map*> maps() const;
  // The map with this id, or null (removed, e.g. merged into another, or never created).
  Map* FindMap(MapId id) const;
  int NumMaps() const { return static_cast<int>(maps_.size()); }

  // The keyframe database over all maps (place recognition); null until set. Guarded by the
  // Atlas mutex like the rest of the map model. Every map created afterwards uses it.
  void SetDatabase(std::unique_ptr<KeyFrameDatabase> database);
  KeyFrameDatabase* database() const { return database_.get(); }

  // Id counters (thread-safe, deterministic: ids increase by one per call).
  FrameId NextFrameId() { return next_frame_id_.fetch_add(1); }
  KeyFrameId NextKeyFrameId() { return next_kf_id_.fetch_add(1); }
  MapPointId NextMapPointId() { return next_point_id_.fetch_add(1); }

  // The calibration every keyframe's keypoints are in, and the rig built from it (online
  // calibration, mapping/calibration_refinement.h): each keyframe's rig() is rig_setup().rig.
  // Read under the shared lock, set under the write lock; calibration_version() (bumped by
  // every set) needs no lock, so tracking can poll it per frame.
  const RigCalibration& calibration() const { return calibration_; }
  const RigSetup& rig_setup() const { return rig_setup_; }
  void SetCalibration(const MapWriteLock& lock, RigCalibration calibration, RigSetup setup);
  int calibration_version() const { return calibration_version_.load(); }

  // Exclusive holds of the map lock so far, per kind of change (thread-safe; no lock needed).
  MapEditTable EditStats() const;

 private:
  friend class AtlasStorage;  // map files: map_model/storage/atlas_storage.h
  friend class MapEditor;
  friend class MapReader;
  friend class MapReadLock;
  friend class MapWriteLock;
  void RecordEdit(MapEdit edit, double held_s) const;
  Map* AddMap();
  // Throws Error unless `lock` holds this Atlas exclusively.
  void RequireWriteLock(const MapWriteLock& lock, const char* operation) const;

  // Shared: read the map model. Exclusive: change it. Taken only by MapReader / MapEditor.
  mutable std::shared_mutex mutex_;
  // Guards edit_stats_ (written when a MapWriteLock ends, read by EditStats()).
  mutable Mutex edit_stats_mutex_;
  mutable MapEditTable edit_stats_ PKSLAM_GUARDED_BY(edit_stats_mutex_){};
  std::unique_ptr<KeyFrameDatabase> database_;  // declared before maps_: outlives them
  std::vector<std::unique_ptr<Map>> maps_;
  Map* current_ = nullptr;
  MapId next_map_id_ = 0;
  RigCalibration calibration_;
  RigSetup rig_setup_;
  std::atomic<int> calibration_version_{0};
  std::atomic<FrameId> next_frame_id_{0};
  std::atomic<KeyFrameId> next_kf_id_{0};
  std::atomic<MapPointId> next_point_id_{0};
};

}  // namespace pkslam
