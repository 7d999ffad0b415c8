// A 3-D landmark: position, representative descriptor, viewing direction and scale range,
// and which keyframes observe it.
//
// Threading (docs/architecture.md): everything except the visible/found counters is guarded by
// the Atlas mutex — read under a shared lock, written under an exclusive lock: every change
// takes the write lock (MapWriteLock) as a parameter and throws without it, except set_map (as
// KeyFrame's). The counters are atomics because tracking bumps them while holding only a
// shared lock.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <map>
#include <memory>

#include "core/features/descriptor.h"
#include "core/sensor/scale_pyramid.h"
#include "map_model/map_ids.h"

namespace pkslam {

class MapWriteLock;

class MapPoint : public std::enable_shared_from_this<MapPoint> {
 public:
  MapPoint(MapPointId id, const Eigen::Vector3d& position_world, KeyFrame* reference_kf, Map* map);
  // A point for one frame's visual odometry (localisation only, where the loaded map has no
  // points to track): a stereo/RGB-D keypoint's position and descriptor, no id, no map, no
  // observations. It never enters a map; tracking drops it after the frame.
  static MapPointPtr Temporary(const Eigen::Vector3d& position_world, const Descriptor& descriptor);
  MapPoint(const MapPoint&) = delete;
  MapPoint& operator=(const MapPoint&) = delete;

  MapPointId id() const { return id_; }
  Map* map() const { return map_; }
  void set_map(Map* map) { map_ = map; }
  KeyFrameId first_keyframe_id() const { return first_kf_id_; }

  const Eigen::Vector3d& position() const { return position_; }
  // Moves the point (adjustments, loop correction, a rescaled map); throws without the write
  // lock.
  void SetPosition(const MapWriteLock& lock, const Eigen::Vector3d& p);
  // Mean unit direction from the observing cameras to the point.
  const Eigen::Vector3d& normal() const { return normal_; }
  const Descriptor& descriptor() const { return descriptor_; }
  // Scale-invariance distance range: the point can be matched from [min, max] metres.
  double min_distance() const { return 0.8 * min_distance_; }
  double max_distance() const { return 1.2 * max_distance_; }

  // --- observations (keyframe id order => deterministic iteration) ---
  struct Observation {
    KeyFrame* keyframe = nullptr;  // non-owning; valid while the observation exists
    int index = -1;                // keypoint index in that keyframe
  };
  const std::map<KeyFrameId, Observation>& observations() const { return observations_; }
  // Stereo/RGB-D observations count twice (as in ORB-SLAM).
  int NumObservations() const { return num_obs_; }
  // Observation edits take the write lock and throw without it (the point's observations are
  // read by tracking and loop closing under the shared lock).
  void AddObservation(const MapWriteLock& lock, KeyFrame* kf, int index);
  // Returns true if the point has become bad (fewer than 3 observation units left); the point
  // is then retired from its keyframes and its map under the same lock.
  bool EraseObservation(const MapWriteLock& lock, KeyFrame* kf);
  bool IsInKeyFrame(const KeyFrame* kf) const;
  int IndexInKeyFrame(const KeyFrame* kf) const;  // -1 if not observed there

  KeyFrame* reference_keyframe() const { return reference_kf_; }

  // Marks the point bad and removes it from all observing keyframes and from its map; throws
  // without the write lock. Must be owned by a MapPointPtr (the call keeps itself alive while
  // unlinking).
  void SetBad(const MapWriteLock& lock);
  bool IsBad() const { return bad_; }
  // Fuse: moves all observations to `other` (which survives) and marks this one bad; throws
  // without the write lock.
  void Replace(const MapWriteLock& lock, const MapPointPtr& other);
  // The point this one was fused into (follow the chain), or nullptr.
  MapPointPtr replaced_by() const { return replaced_by_; }

  // Median-distance descriptor among all observations.
  void ComputeDistinctiveDescriptor(const MapWriteLock& lock);
  // Recomputes the normal and the distance range from the observations.
  void UpdateNormalAndDepth(const MapWriteLock& lock);
  // Pyramid level at which the point is expected when seen from `distance` metres.
  int PredictScale(double distance, const ScalePyramid& pyramid) const;

  // --- statistics written by tracking (atomic) ---
  void IncreaseVisible(int n = 1) { visible_.fetch_add(n, std::memory_order_relaxed); }
  void IncreaseFound(int n = 1) { found_.fetch_add(n, std::memory_order_relaxed); }
  int visible() const { return visible_.load(std::memory_order_relaxed); }
  int found() const { return found_.load(std::memory_order_relaxed); }
  double FoundRatio() const { return static_cast<double>(found()) / std::max(1, visible()); }

 private:
  friend class AtlasStorage;  // map files: map_model/storage/atlas_storage.h
  // AddObservation's work once the lock is checked (Replace moves observations under the lock
  // it checked).
  void Observe(KeyFrame* kf, int index);
  // SetBad's work; EraseObservation retires a point left with too few observations.
  void Retire(const MapWriteLock& lock);

  MapPointId id_;
  KeyFrameId first_kf_id_;
  Map* map_;
  Eigen::Vector3d position_;
  Eigen::Vector3d normal_ = Eigen::Vector3d::Zero();
  Descriptor descriptor_;
  double min_distance_ = 0;
  double max_distance_ = 0;
  std::map<KeyFrameId, Observation> observations_;
  int num_obs_ = 0;
  KeyFrame* reference_kf_;
  bool bad_ = false;
  MapPointPtr replaced_by_;
  std::atomic<int> visible_{1};
  std::atomic<int> found_{1};
};

}  // namespace pkslam
