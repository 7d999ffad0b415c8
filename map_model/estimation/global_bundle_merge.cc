#include "map_model/estimation/global_bundle_merge.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <set>

#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"

namespace pkslam {

void MergeGlobalBundle(const MapWriteLock& lock, Map* map, const BundleProblem& problem,
                       const BundleResult& result) {
  MergeGlobalBundle(
      lock, map, problem, [&] { ApplyBundle(lock, map, problem, result); }, false);
}

void MergeGlobalBundle(const MapWriteLock& lock, Map* map, const BundleProblem& problem,
                       const std::function<void()>& apply, bool apply_sets_velocities) {
  RequireWriteLock(lock, "MergeGlobalBundle");
  if (map == nullptr || map->origin() == nullptr) return;
  // Poses before the write-back: what everything outside the problem is relative to.
  std::map<KeyFrameId, SE3d> before;
  for (const auto& [id, kf] : map->keyframes()) before[id] = kf->camera_from_world();
  std::set<KeyFrameId> in_problem;
  // (A keyframe that left the map meanwhile is skipped below by its map() test.)
  for (const auto& k : problem.keyframes) in_problem.insert(k.keyframe_id);
  std::set<MapPointId> points_in_problem;
  for (const auto& p : problem.points) points_in_problem.insert(p.point_id);

  apply();

  // Keyframes created while the BA ran: breadth-first down the spanning tree, each keeps its
  // pose relative to its (already updated) parent.
  std::deque<KeyFrame*> open{map->origin()};
  std::set<KeyFrameId> seen{map->origin()->id()};
  while (!open.empty()) {
    KeyFrame* parent = open.front();
    open.pop_front();
    for (const auto& [child_id, child] : parent->children()) {
      if (!seen.insert(child_id).second) continue;
      open.push_back(child);
      if (child->IsBad() || child->map() != map || in_problem.count(child_id) > 0) continue;
      const auto child_before = before.find(child_id);
      const auto parent_before = before.find(parent->id());
      if (child_before == before.end() || parent_before == before.end()) continue;
      const SE3d child_from_parent = child_before->second * parent_before->second.Inverse();
      child->SetPose(lock, child_from_parent * parent->camera_from_world());
    }
  }

  // Velocities (inertial maps) turn with their keyframe's orientation.
  for (const auto& [id, kf] : map->keyframes()) {
    const auto it = before.find(id);
    if (kf->IsBad() || !kf->imu().state.valid || it == before.end()) continue;
    if (apply_sets_velocities && in_problem.count(id) > 0) continue;
    kf->mutable_imu(lock).state.velocity_world =
        kf->world_from_camera().so3() * (it->second.so3() * kf->imu().state.velocity_world);
  }

  // Points created meanwhile move rigidly with their reference keyframe.
  for (const auto& [id, mp] : map->map_points()) {
    if (mp->IsBad() || points_in_problem.count(id) > 0) continue;
    KeyFrame* ref = mp->reference_keyframe();
    if (ref == nullptr) continue;
    const auto ref_before = before.find(ref->id());
    if (ref_before == before.end()) continue;
    mp->SetPosition(lock, ref->world_from_camera() * (ref_before->second * mp->position()));
    mp->UpdateNormalAndDepth(lock);
  }
  map->IncreaseChangeIndex(lock);
}

std::map<KeyFrameId, Eigen::Vector3d> GravityInCameras(const Map& map) {
  std::map<KeyFrameId, Eigen::Vector3d> out;
  for (const auto& [id, kf] : map.keyframes()) {
    if (!kf->IsBad()) out[id] = kf->camera_from_world().so3() * Eigen::Vector3d::UnitZ();
  }
  return out;
}

double MaxTiltChange(const Map& map, const std::map<KeyFrameId, Eigen::Vector3d>& before) {
  double worst = 0;
  for (const auto& [id, g] : GravityInCameras(map)) {
    auto it = before.find(id);
    if (it == before.end()) continue;
    worst = std::max(worst, std::atan2(g.cross(it->second).norm(), g.dot(it->second)));
  }
  return worst;
}

}  // namespace pkslam
