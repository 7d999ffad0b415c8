#include "map_model/map.h"

#include "map_model/keyframe.h"
#include "map_model/keyframe_database.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"

namespace pkslam {

Map::~Map() { Clear(); }

void Map::AddKeyFrame(const MapWriteLock& lock, const KeyFramePtr& kf) {
  RequireWriteLock(lock, "Map::AddKeyFrame");
  if (keyframes_.empty() && origin_ == nullptr) origin_ = kf.get();
  keyframes_[kf->id()] = kf;
  if (kf->id() > max_kf_id_) max_kf_id_ = kf->id();
}

void Map::AddRetiredKeyFrame(const MapWriteLock& lock, const KeyFramePtr& kf) {
  RequireWriteLock(lock, "Map::AddRetiredKeyFrame");
  retired_[kf->id()] = kf;
  if (kf->id() > max_kf_id_) max_kf_id_ = kf->id();
}

void Map::AddMapPoint(const MapWriteLock& lock, const MapPointPtr& point) {
  RequireWriteLock(lock, "Map::AddMapPoint");
  map_points_[point->id()] = point;
}

MapPointPtr Map::CreateMapPoint(const MapWriteLock& lock, MapPointId id,
                                const Eigen::Vector3d& position_world, KeyFrame* reference,
                                std::initializer_list<MapPoint::Observation> observations) {
  RequireWriteLock(lock, "Map::CreateMapPoint");
  auto point = std::make_shared<MapPoint>(id, position_world, reference, this);
  for (const MapPoint::Observation& o : observations) {
    point->AddObservation(lock, o.keyframe, o.index);
    o.keyframe->AddMapPoint(lock, point, o.index);
  }
  point->ComputeDistinctiveDescriptor(lock);
  point->UpdateNormalAndDepth(lock);
  map_points_[id] = point;
  return point;
}

void Map::IncreaseChangeIndex(const MapWriteLock& lock) {
  RequireWriteLock(lock, "Map::IncreaseChangeIndex");
  ++change_index_;
}

MapImuStatus& Map::mutable_imu_status(const MapWriteLock& lock) {
  RequireWriteLock(lock, "Map::mutable_imu_status");
  return imu_status_;
}

void Map::EraseMapPoint(const MapPoint* point) { map_points_.erase(point->id()); }

void Map::RetireKeyFrame(const MapWriteLock& lock, const KeyFrame* kf) {
  auto it = keyframes_.find(kf->id());
  if (it == keyframes_.end()) return;
  if (database_ != nullptr) database_->Erase(lock, kf);
  retired_[kf->id()] = std::move(it->second);
  keyframes_.erase(it);
}

KeyFramePtr Map::TakeKeyFrame(const KeyFrame* kf) {
  for (auto* set : {&keyframes_, &retired_}) {
    auto it = set->find(kf->id());
    if (it != set->end()) {
      KeyFramePtr out = std::move(it->second);
      set->erase(it);
      if (origin_ == kf) origin_ = nullptr;
      return out;
    }
  }
  return nullptr;
}

MapPointPtr Map::TakeMapPoint(const MapPoint* point) {
  auto it = map_points_.find(point->id());
  if (it == map_points_.end()) return nullptr;
  MapPointPtr out = std::move(it->second);
  map_points_.erase(it);
  return out;
}

KeyFramePtr Map::FindKeyFrame(KeyFrameId id) const {
  if (KeyFramePtr live = KeyFrameById(id)) return live;
  const auto it = retired_.find(id);
  return it == retired_.end() ? nullptr : it->second;
}

KeyFramePtr Map::KeyFrameById(KeyFrameId id) const {
  const auto it = keyframes_.find(id);
  return it == keyframes_.end() ? nullptr : it->second;
}

MapPointPtr Map::MapPointById(MapPointId id) const {
  const auto it = map_points_.find(id);
  return it == map_points_.end() ? nullptr : it->second;
}

KeyFramePtr Map::Share(const KeyFrame* kf) const {
  KeyFramePtr live = KeyFrameById(kf->id());
  return live.get() == kf ? live : nullptr;
}

MapPointPtr Map::Share(const MapPoint* point) const {
  MapPointPtr live = MapPointById(point->id());
  return live.get() == point ? live : nullptr;
}

void Map::RecordWorldChange(const MapWriteLock& lock, const WorldChange& change) {
  RequireWriteLock(lock, "Map::RecordWorldChange");
  world_changes_.push_back(change);
  if (change.kind == WorldChange::Kind::kTransform) {
    applied_scale_ *= change.scale;
    ++world_transforms_;
  }
}

void Map::Clear() {
  if (database_ != nullptr) database_->Clear(this);
  // Keyframes hold points and points point back at keyframes: unlink before releasing so
  // nothing outlives the map holding a dangling back reference.
  for (auto& [id, point] : map_points_) point->set_map(nullptr);
  map_points_.clear();
  for (auto* set : {&keyframes_, &retired_}) {
    for (auto& [id, kf] : *set) kf->set_map(nullptr);
    set->clear();
  }
  origin_ = nullptr;
  max_kf_id_ = kInvalidId;
}

}  // namespace pkslam
