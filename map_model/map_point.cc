#include "map_model/map_point.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"

namespace pkslam {

MapPoint::MapPoint(MapPointId id, const Eigen::Vector3d& position_world, KeyFrame* reference_kf,
                   Map* map)
    : id_(id),
      first_kf_id_(reference_kf != nullptr ? reference_kf->id() : kInvalidId),
      map_(map),
      position_(position_world),
      reference_kf_(reference_kf) {}

MapPointPtr MapPoint::Temporary(const Eigen::Vector3d& position_world,
                                const Descriptor& descriptor) {
  auto point = std::make_shared<MapPoint>(kInvalidId, position_world, nullptr, nullptr);
  point->descriptor_ = descriptor;
  return point;
}

void MapPoint::SetPosition(const MapWriteLock& lock, const Eigen::Vector3d& p) {
  RequireWriteLock(lock, "MapPoint::SetPosition");
  position_ = p;
}

void MapPoint::AddObservation(const MapWriteLock& lock, KeyFrame* kf, int index) {
  RequireWriteLock(lock, "MapPoint::AddObservation");
  Observe(kf, index);
}

void MapPoint::Observe(KeyFrame* kf, int index) {
  auto [it, inserted] = observations_.try_emplace(kf->id(), Observation{kf, index});
  if (!inserted) return;
  num_obs_ += kf->HasDepth(index) ? 2 : 1;
}

bool MapPoint::EraseObservation(const MapWriteLock& lock, KeyFrame* kf) {
  RequireWriteLock(lock, "MapPoint::EraseObservation");
  auto it = observations_.find(kf->id());
  if (it == observations_.end()) return false;
  num_obs_ -= kf->HasDepth(it->second.index) ? 2 : 1;
  observations_.erase(it);
  if (reference_kf_ == kf) {
    reference_kf_ = observations_.empty() ? nullptr : observations_.begin()->second.keyframe;
  }
  // Fewer than three observation units cannot constrain the point any more.
  if (num_obs_ <= 2) {
    Retire(lock);
    return true;
  }
  return false;
}

bool MapPoint::IsInKeyFrame(const KeyFrame* kf) const { return observations_.count(kf->id()) > 0; }

int MapPoint::IndexInKeyFrame(const KeyFrame* kf) const {
  auto it = observations_.find(kf->id());
  return it == observations_.end() ? -1 : it->second.index;
}

void MapPoint::SetBad(const MapWriteLock& lock) {
  RequireWriteLock(lock, "MapPoint::SetBad");
  Retire(lock);
}

void MapPoint::Retire(const MapWriteLock& lock) {
  if (bad_) return;
  const MapPointPtr keep_alive = shared_from_this();
  bad_ = true;
  const auto observations = std::move(observations_);
  observations_.clear();
  num_obs_ = 0;
  for (const auto& [id, obs] : observations) obs.keyframe->EraseMapPointMatch(lock, obs.index);
  if (map_ != nullptr) map_->EraseMapPoint(this);
}

void MapPoint::Replace(const MapWriteLock& lock, const MapPointPtr& other) {
  RequireWriteLock(lock, "MapPoint::Replace");
  if (other.get() == this || bad_) return;
  const MapPointPtr keep_alive = shared_from_this();
  const auto observations = std::move(observations_);
  observations_.clear();
  num_obs_ = 0;
  bad_ = true;
  replaced_by_ = other;
  for (const auto& [id, obs] : observations) {
    if (!other->IsInKeyFrame(obs.keyframe)) {
      obs.keyframe->ReplaceMapPointMatch(lock, obs.index, other);
      other->Observe(obs.keyframe, obs.index);
    } else {
      obs.keyframe->EraseMapPointMatch(lock, obs.index);
    }
  }
  other->IncreaseFound(found());
  other->IncreaseVisible(visible());
  other->ComputeDistinctiveDescriptor(lock);
  if (map_ != nullptr) map_->EraseMapPoint(this);
}

void MapPoint::ComputeDistinctiveDescriptor(const MapWriteLock& lock) {
  RequireWriteLock(lock, "MapPoint::ComputeDistinctiveDescriptor");
  if (bad_ || observations_.empty()) return;
  std::vector<const Descriptor*> descriptors;
  descriptors.reserve(observations_.size());
  for (const auto& [id, obs] : observations_) {
    if (!obs.keyframe->IsBad()) descriptors.push_back(&obs.keyframe->descriptors()[obs.index]);
  }
  const std::size_t n = descriptors.size();
  if (n == 0) return;
  // The descriptor with the least median distance to the others.
  std::vector<int> distances(n * n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const int d = HammingDistance(*descriptors[i], *descriptors[j]);
      distances[i * n + j] = d;
      distances[j * n + i] = d;
    }
  }
  int best_median = 256;
  std::size_t best = 0;
  std::vector<int> row(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::copy(distances.begin() + i * n, distances.begin() + (i + 1) * n, row.begin());
    std::nth_element(row.begin(), row.begin() + (n - 1) / 2, row.end());
    const int median = row[(n - 1) / 2];
    if (median < best_median) {
      best_median = median;
      best = i;
    }
  }
  descriptor_ = *descriptors[best];
}

void MapPoint::UpdateNormalAndDepth(const MapWriteLock& lock) {
  RequireWriteLock(lock, "MapPoint::UpdateNormalAndDepth");
  if (bad_ || observations_.empty() || reference_kf_ == nullptr) return;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& [id, obs] : observations_) {
    const Eigen::Vector3d ray = position_ - obs.keyframe->CameraCenter();
    const double norm = ray.norm();
    if (norm <= 0) continue;
    normal += ray / norm;
    ++n;
  }
  if (n == 0) return;
  normal_ = normal / n;
  const int ref_index = IndexInKeyFrame(reference_kf_);
  if (ref_index < 0) return;
  const double distance = (position_ - reference_kf_->CameraCenter()).norm();
  const ScalePyramid& pyramid = reference_kf_->rig().pyramid;
  const int level = reference_kf_->keypoints_undistorted()[ref_index].octave;
  max_distance_ = distance * pyramid.scale[level];
  min_distance_ = max_distance_ / pyramid.scale[pyramid.n_levels - 1];
}

int MapPoint::PredictScale(double distance, const ScalePyramid& pyramid) const {
  const double ratio = max_distance_ / distance;
  const int level = static_cast<int>(std::ceil(std::log(ratio) / pyramid.log_scale_factor));
  return std::clamp(level, 0, pyramid.n_levels - 1);
}

}  // namespace pkslam
