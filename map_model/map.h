// One map of the Atlas: its live keyframes and map points (owned, id-ordered), its retired
// keyframes (kept for trajectory reconstruction), and per-map state (IMU initialisation,
// change counter for loop corrections). Guarded by the Atlas mutex.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <initializer_list>
#include <map>
#include <memory>
#include <vector>

#include "core/geometry/so3.h"
#include "map_model/inertial_chain.h"
#include "map_model/map_ids.h"
#include "map_model/map_point.h"
#include "map_model/world_change.h"

namespace pkslam {

class KeyFrameDatabase;
class MapWriteLock;

// How far a map's IMU initialisation has come.
struct MapImuStatus {
  bool imu_initialized = false;
  bool inertial_ba1_done = false;
  bool inertial_ba2_done = false;
  // Tilt observability (estimators/inertial/gravity_gauge.h) of the chain at the last gravity
  // refinement (0: none yet).
  double gravity_refinement_observability = 0;
  // Time of the first keyframe of the IMU initialisation [ns].
  std::int64_t imu_init_t_ns = 0;
};

class Map {
 public:
  explicit Map(MapId id) : id_(id) {}
  Map(const Map&) = delete;
  Map& operator=(const Map&) = delete;
  ~Map();

  MapId id() const { return id_; }

  // The changes below take the Atlas's write lock (map_editor.h) and throw Error without it.
  void AddKeyFrame(const MapWriteLock& lock, const KeyFramePtr& kf);
  // Takes over a keyframe retired in another map (map merging).
  void AddRetiredKeyFrame(const MapWriteLock& lock, const KeyFramePtr& kf);
  void AddMapPoint(const MapWriteLock& lock, const MapPointPtr& point);
  // The one way a point is born (tracking's stereo/depth points and two-view start, local
  // mapping's triangulation): a live point at `position_world` seen at each keyframe keypoint of
  // `observations`, which take it in their (empty) slots; its descriptor, normal and depth range
  // are computed from them. `reference`: the keyframe its scale range is measured from.
  MapPointPtr CreateMapPoint(const MapWriteLock& lock, MapPointId id,
                             const Eigen::Vector3d& position_world, KeyFrame* reference,
                             std::initializer_list<MapPoint::Observation> observations);
  // Removes the point from the live set (callers mark it bad first).
  void EraseMapPoint(const MapPoint* point);
  // Moves a keyframe from the live set to the retired set (KeyFrame::SetBad calls this).
  void RetireKeyFrame(const MapWriteLock& lock, const KeyFrame* kf);
  // Moves a keyframe out of this map entirely (map merging); returns the owning pointer.
  KeyFramePtr TakeKeyFrame(const KeyFrame* kf);
  MapPointPtr TakeMapPoint(const MapPoint* point);

  const std::map<KeyFrameId, KeyFramePtr>& keyframes() const { return keyframes_; }
  const std::map<KeyFrameId, KeyFramePtr>& retired_keyframes() const { return retired_; }
  const std::map<MapPointId, MapPointPtr>& map_points() const { return map_points_; }
  int NumKeyFrames() const { return static_cast<int>(keyframes_.size()); }
  int NumMapPoints() const { return static_cast<int>(map_points_.size()); }
  // Live or retired keyframe by id, or nullptr.
  KeyFramePtr FindKeyFrame(KeyFrameId id) const;
  // The keyframe / map point of this map with this id, or nullptr (never here, moved to another
  // map by a merge, or for a point: retired). How results of estimators, which name objects by
  // id, find their way back. Shared: a caller that may retire objects keeps them alive.
  KeyFramePtr KeyFrameById(KeyFrameId id) const;
  MapPointPtr MapPointById(MapPointId id) const;
  // The owning pointer of a live keyframe / map point (nullptr if not live here).
  KeyFramePtr Share(const KeyFrame* kf) const;
  MapPointPtr Share(const MapPoint* point) const;

  // The first keyframe of the map (never retired), or nullptr.
  KeyFrame* origin() const { return origin_; }
  KeyFrameId max_keyframe_id() const { return max_kf_id_; }

  // Bumped by loop closing / global BA so tracking knows poses moved under it, and by local
  // mapping's full inertial BA (it invalidates the local inertial BA's marginalisation priors).
  int change_index() const { return change_index_; }
  void IncreaseChangeIndex(const MapWriteLock& lock);

  // Inertial state of the map: read by every thread under the Atlas lock, written by local
  // mapping (IMU initialisation and refinements) and loop closing (merges) under its write lock.
  const MapImuStatus& imu_status() const { return imu_status_; }
  MapImuStatus& mutable_imu_status(const MapWriteLock& lock);

  // World changes (world_change.h): recorded by whoever changed the map, read by tracking past
  // its cursor. A transform also multiplies the applied scale.
  void RecordWorldChange(const MapWriteLock& lock, const WorldChange& change);
  int NumWorldChanges() const { return static_cast<int>(world_changes_.size()); }
  const WorldChange& world_change(int index) const { return world_changes_.at(index); }
  // Product of the scale factors applied to the map (monocular-inertial initialisation), so
  // tracking can rescale what it stores relative to keyframes.
  double applied_scale() const { return applied_scale_; }
  // How many transforms the map underwent (marginalisation priors expire with each).
  int NumWorldTransforms() const { return world_transforms_; }

  // The temporal keyframe chain of an inertial map: the one way to link, splice or cut it.
  const InertialChain& inertial_chain() const { return inertial_chain_; }

  // Drops everything (used on reset). Breaks every keyframe<->point link first.
  void Clear();

  // The place-recognition index keyframes are erased from when retired (owned by the Atlas).
  void set_database(KeyFrameDatabase* database) { database_ = database; }
  KeyFrameDatabase* database() const { return database_; }

 private:
  friend class AtlasStorage;  // map files: map_model/storage/atlas_storage.h
  MapId id_;
  std::map<KeyFrameId, KeyFramePtr> keyframes_;
  std::map<KeyFrameId, KeyFramePtr> retired_;
  std::map<MapPointId, MapPointPtr> map_points_;
  KeyFrame* origin_ = nullptr;
  KeyFrameId max_kf_id_ = kInvalidId;
  int change_index_ = 0;
  KeyFrameDatabase* database_ = nullptr;
  InertialChain inertial_chain_{this};
  MapImuStatus imu_status_;
  std::vector<WorldChange> world_changes_;
  double applied_scale_ = 1.0;
  int world_transforms_ = 0;
};

}  // namespace pkslam
