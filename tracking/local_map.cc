#include "tracking/local_map.h"

#include <map>
#include <unordered_set>
#include <utility>

#include "map_model/keyframe.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"

namespace pkslam {

KeyFrame* LocalMap::Update(Frame* frame, const Frame* voters) {
  for (MapPointPtr& mp : frame->map_points) {
    if (mp && mp->IsBad()) mp.reset();
  }
  KeyFrame* best = UpdateKeyFrames(voters != nullptr ? *voters : *frame);
  UpdatePoints();
  return best;
}

void LocalMap::Reset(std::vector<KeyFrame*> keyframes, std::vector<MapPointPtr> points) {
  keyframes_ = std::move(keyframes);
  points_ = std::move(points);
}

void LocalMap::Clear() {
  keyframes_.clear();
  points_.clear();
}

KeyFrame* LocalMap::UpdateKeyFrames(const Frame& voters) {
  // Keyframes observing the voters' points, by how many they share.
  std::map<KeyFrameId, std::pair<KeyFrame*, int>> counter;
  for (const MapPointPtr& mp : voters.map_points) {
    if (!mp || mp->IsBad()) continue;
    for (const auto& [id, obs] : mp->observations()) {
      auto& entry = counter[id];
      entry.first = obs.keyframe;
      ++entry.second;
    }
  }
  if (counter.empty()) return nullptr;

  keyframes_.clear();
  std::unordered_set<KeyFrameId> in_local;
  KeyFrame* best = nullptr;
  int best_count = 0;
  for (const auto& [id, entry] : counter) {
    KeyFrame* kf = entry.first;
    if (kf->IsBad()) continue;
    if (entry.second > best_count) {
      best_count = entry.second;
      best = kf;
    }
    keyframes_.push_back(kf);
    in_local.insert(id);
  }
  // Grow by one neighbour, one child and the parent of each (ORB-SLAM), up to the cap.
  auto try_add = [&](KeyFrame* kf) {
    if (kf == nullptr || kf->IsBad() || in_local.count(kf->id()) > 0) return false;
    keyframes_.push_back(kf);
    in_local.insert(kf->id());
    return true;
  };
  const std::size_t initial = keyframes_.size();
  for (std::size_t k = 0; k < initial; ++k) {
    if (static_cast<int>(keyframes_.size()) > max_keyframes_) break;
    KeyFrame* kf = keyframes_[k];
    for (KeyFrame* neighbour : kf->BestCovisibles(10)) {
      if (try_add(neighbour)) break;
    }
    for (const auto& [id, child] : kf->children()) {
      if (try_add(child)) break;
    }
    try_add(kf->parent());
  }
  return best;
}

void LocalMap::UpdatePoints() {
  points_.clear();
  std::unordered_set<MapPointId> seen;
  for (KeyFrame* kf : keyframes_) {
    for (const auto& mp : kf->map_points()) {
      if (!mp || mp->IsBad()) continue;
      if (seen.insert(mp->id()).second) points_.push_back(mp);
    }
  }
}

int LocalMap::Search(Frame* frame, const CameraRig& rig, double radius) const {
  std::unordered_set<MapPointId> already;
  for (int i = 0; i < frame->size(); ++i) {
    auto& mp = frame->map_points[i];
    if (!mp) continue;
    if (mp->IsBad()) {
      mp.reset();
      continue;
    }
    mp->IncreaseVisible();
    already.insert(mp->id());
  }
  const SE3d& tcw = frame->camera_from_world();
  const Eigen::Vector3d center = frame->CameraCenter();
  std::vector<ProjectedPoint> projected;
  projected.reserve(points_.size());
  for (const auto& mp : points_) {
    if (already.count(mp->id()) > 0 || mp->IsBad()) continue;
    // Frustum test (ORB-SLAM's Frame::isInFrustum with a 60 degree viewing-angle limit).
    const Eigen::Vector3d p = mp->position();
    const Eigen::Vector3d pc = tcw * p;
    if (pc.z() <= 0) continue;
    const double inv_z = 1.0 / pc.z();
    const double u = rig.fx * pc.x() * inv_z + rig.cx;
    const double v = rig.fy * pc.y() * inv_z + rig.cy;
    if (!rig.bounds.Contains(u, v)) continue;
    const Eigen::Vector3d ray = p - center;
    const double distance = ray.norm();
    if (distance < mp->min_distance() || distance > mp->max_distance()) continue;
    const double view_cos = ray.dot(mp->normal()) / distance;
    if (view_cos < 0.5) continue;
    mp->IncreaseVisible();
    ProjectedPoint pp;
    pp.point = mp;
    pp.u = u;
    pp.v = v;
    pp.u_right = IsMonocular(rig.sensor) ? -1.0 : u - rig.bf * inv_z;
    pp.predicted_level = mp->PredictScale(distance, rig.pyramid);
    pp.view_cos = view_cos;
    pp.depth = pc.z();
    projected.push_back(std::move(pp));
  }
  if (projected.empty()) return 0;
  const OrbMatcher matcher(0.8, true);
  return matcher.SearchByProjection(frame, projected, radius);
}

}  // namespace pkslam
