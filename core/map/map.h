// One map of the Atlas: its live keyframes and map points (owned, id-ordered), its retired
// keyframes (kept for trajectory reconstruction), and per-map state (IMU initialisation,
// change counter for loop corrections). Guarded by the Atlas mutex.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "core/geometry/so3.h"
#include "core/map/ids.h"

namespace pkslam {

class KeyFrameDatabase;

class Map {
 public:
  explicit Map(MapId id) : id_(id) {}
  Map(const Map&) = delete;
  Map& operator=(const Map&) = delete;
  ~Map();

  MapId id() const { return id_; }

  void AddKeyFrame(const KeyFramePtr& kf);
  // Takes over a keyframe retired in another map (map merging).
  void AddRetiredKeyFrame(const KeyFramePtr& kf);
  void AddMapPoint(const MapPointPtr& point);
  // Removes the point from the live set (callers mark it bad first).
  void EraseMapPoint(const MapPoint* point);
  // Moves a keyframe from the live set to the retired set (KeyFrame::SetBad calls this).
  void RetireKeyFrame(const KeyFrame* kf);
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
  // The owning pointer of a live keyframe / map point (nullptr if not live here).
  KeyFramePtr Share(const KeyFrame* kf) const;
  MapPointPtr Share(const MapPoint* point) const;

  // The first keyframe of the map (never retired), or nullptr.
  KeyFrame* origin() const { return origin_; }
  KeyFrameId max_keyframe_id() const { return max_kf_id_; }

  // Bumped by loop closing / global BA so tracking knows poses moved under it, and by local
  // mapping's full inertial BA (it invalidates the local inertial BA's marginalisation priors).
  int change_index() const { return change_index_; }
  void IncreaseChangeIndex() { ++change_index_; }

  // Inertial state of the map.
  bool imu_initialized = false;
  bool inertial_ba1_done = false;
  bool inertial_ba2_done = false;
  // Tilt observability (mapping/gravity_refinement.h) of the chain at the last gravity
  // refinement (0: none yet).
  double gravity_refinement_observability = 0;
  // Time of the first keyframe of the IMU initialisation and of the initialisation [ns].
  std::int64_t imu_init_t_ns = 0;
  // Bumped whenever local mapping rotates / rescales the map or re-estimates keyframe
  // velocities and biases (IMU initialisation, inertial BA): tracking then predicts from the
  // last keyframe instead of the last frame.
  int imu_change_index = 0;
  // Product of the scale factors applied to the map (monocular-inertial initialisation), so
  // tracking can rescale what it stores relative to keyframes.
  double applied_scale = 1.0;
  // Bumped when local mapping rotates / rescales the whole map (x' = scale * rotation * x);
  // the last such change, so tracking can carry a frame tracked just before it across.
  int world_change_index = 0;
  SO3d last_world_rotation;
  double last_world_scale = 1.0;

  // Drops everything (used on reset). Breaks every keyframe<->point link first.
  void Clear();

  // The place-recognition index keyframes are erased from when retired (owned by the Atlas).
  void set_database(KeyFrameDatabase* database) { database_ = database; }
  KeyFrameDatabase* database() const { return database_; }

 private:
  MapId id_;
  std::map<KeyFrameId, KeyFramePtr> keyframes_;
  std::map<KeyFrameId, KeyFramePtr> retired_;
  std::map<MapPointId, MapPointPtr> map_points_;
  KeyFrame* origin_ = nullptr;
  KeyFrameId max_kf_id_ = kInvalidId;
  int change_index_ = 0;
  KeyFrameDatabase* database_ = nullptr;
};

}  // namespace pkslam
