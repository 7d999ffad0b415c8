// LoopClosing: loop correction (ORB-SLAM3's CorrectLoop) and map merging (a simplified
// MergeLocal: the whole current map is moved into the recognised map, then welded).
// Inertial maps with the IMU initialised (gravity along the world's -z) are corrected in 4 DoF:
// the loop / merge transform is reduced to yaw + translation (ProjectToYawTranslation, about
// the query's camera centre, scale 1) and the essential graph runs in kYawTranslation, so
// roll and pitch of every keyframe stay as the IMU estimated them; velocities turn with their
// keyframes (the essential graph's Apply), biases are kept.
#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <set>
#include <shared_mutex>

#include "core/util/log.h"
#include "estimators/optim/yaw_manifold.h"
#include "loopclosing/loop_closing.h"
#include "map_model/estimation/essential_graph_collect.h"
#include "map_model/estimation/global_bundle_merge.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"

namespace pkslam {
namespace {

// Follows fusion forwards to the surviving point (nullptr if it died without a successor).
MapPointPtr Surviving(MapPointPtr mp) {
  while (mp && mp->IsBad()) mp = mp->replaced_by();
  return mp;
}

std::vector<KeyFrame*> Neighbourhood(KeyFrame* query) {
  std::vector<KeyFrame*> out = query->ConnectedKeyFrames();
  out.push_back(query);
  return out;
}

}  // namespace

bool LoopClosing::UsesFourDof(const Map& map) const {
  return IsInertial(sensor_) && map.imu_status().imu_initialized;
}

PoseGraphDof LoopClosing::GraphDof(const Map& map) const {
  if (UsesFourDof(map)) return PoseGraphDof::kYawTranslation;
  return options_.verifier.fix_scale ? PoseGraphDof::kSE3 : PoseGraphDof::kSim3;
}

bool LoopClosing::AcceptsInertialLoop(const CommonRegion& region) const {
  const Map* map = region.query->map();
  if (map == nullptr || !UsesFourDof(*map)) return true;
  const Sim3d world_new_from_world_old =
      region.query_camera_from_world.Inverse() * Sim3d(region.query->camera_from_world());
  const Eigen::Vector3d phi = world_new_from_world_old.so3().Log();
  const bool ok = std::abs(phi.x()) < options_.inertial_max_tilt_rad &&
                  std::abs(phi.y()) < options_.inertial_max_tilt_rad &&
                  std::abs(phi.z()) < options_.inertial_max_yaw_rad;
  if (!ok) {
    PKSLAM_LOG_INFO(
        "inertial loop keyframe {} <-> {} refused: correction rotation ({:.4f} {:.4f} {:.4f}) "
        "rad tilts gravity or turns too far",
        region.query->id(), region.matched->id(), phi.x(), phi.y(), phi.z());
  }
  return ok;
}

bool LoopClosing::AcceptsLoopCorrection(const CommonRegion& region) const {
  const Map* map = region.query->map();
  if (map == nullptr || options_.max_loop_correction_ratio <= 0) return true;
  if (IsMonocular(sensor_) && !UsesFourDof(*map)) return true;  // scale drifts: no metric bound
  const KeyFrameId first = std::min(region.matched->id(), region.query->id());
  const KeyFrameId last = std::max(region.matched->id(), region.query->id());
  double path_m = 0;
  const KeyFrame* previous = nullptr;
  for (auto it = map->keyframes().lower_bound(first);
       it != map->keyframes().end() && it->first <= last; ++it) {
    if (it->second->IsBad()) continue;
    if (previous != nullptr)
      path_m += (it->second->CameraCenter() - previous->CameraCenter()).norm();
    previous = it->second.get();
  }
  const Eigen::Vector3d corrected_centre =
      region.query_camera_from_world.Inverse() * Eigen::Vector3d::Zero();
  const double moved_m = (corrected_centre - region.query->CameraCenter()).norm();
  const double bound_m =
      options_.max_loop_correction_m + options_.max_loop_correction_ratio * path_m;
  if (moved_m <= bound_m) return true;
  PKSLAM_LOG_INFO(
      "loop keyframe {} <-> {} refused: it would move the keyframe {:.3f} m after {:.2f} m of "
      "travel (bound {:.3f} m)",
      region.query->id(), region.matched->id(), moved_m, path_m, bound_m);
  return false;
}

std::map<KeyFrameId, std::vector<KeyFrameId>> LoopClosing::FuseRegion(
    const MapWriteLock& lock, const CommonRegion& region,
    const std::vector<KeyFrame*>& neighbourhood,
    const std::map<KeyFrameId, Sim3d>& camera_from_world) {
  std::map<KeyFrameId, std::set<KeyFrameId>> before;
  std::set<KeyFrameId> in_neighbourhood;
  for (KeyFrame* kf : neighbourhood) {
    in_neighbourhood.insert(kf->id());
    for (KeyFrame* c : kf->ConnectedKeyFrames()) before[kf->id()].insert(c->id());
  }

  // The query's own matches: the other side's point takes over the keypoint.
  KeyFrame* query = region.query.get();
  for (int i = 0; i < query->size(); ++i) {
    const MapPointPtr other = Surviving(region.matched_points[static_cast<std::size_t>(i)]);
    if (!other) continue;
    const MapPointPtr mine = query->map_point(i);
    if (mine && !mine->IsBad()) {
      if (mine != other) mine->Replace(lock, other);
    } else if (!other->IsInKeyFrame(query)) {
      query->AddMapPoint(lock, other, i);
      other->AddObservation(lock, query, i);
      other->ComputeDistinctiveDescriptor(lock);
    }
  }

  // Every keyframe of the neighbourhood: the other side's points projected with its corrected
  // pose replace what the keyframe has at the same place (ORB-SLAM3's SearchAndFuse).
  std::vector<MapPointPtr> others;
  for (const auto& mp : region.window_points) {
    if (MapPointPtr s = Surviving(mp)) others.push_back(std::move(s));
  }
  const OrbMatcher matcher(0.8, true);
  for (KeyFrame* kf : neighbourhood) {
    if (kf->IsBad()) continue;
    std::vector<MapPointPtr> replace;
    matcher.Fuse(lock, kf, camera_from_world.at(kf->id()), others, options_.fuse_radius, &replace);
    for (std::size_t i = 0; i < others.size(); ++i) {
      if (replace[i] && !replace[i]->IsBad() && !others[i]->IsBad() && replace[i] != others[i]) {
        replace[i]->Replace(lock, others[i]);
      }
    }
  }

  std::map<KeyFrameId, std::vector<KeyFrameId>> links;
  for (KeyFrame* kf : neighbourhood) {
    if (kf->IsBad()) continue;
    kf->UpdateConnections(lock);
  }
  for (KeyFrame* kf : neighbourhood) {
    if (kf->IsBad()) continue;
    for (KeyFrame* c : kf->ConnectedKeyFrames()) {
      if (before[kf->id()].count(c->id()) > 0 || in_neighbourhood.count(c->id()) > 0) continue;
      links[kf->id()].push_back(c->id());
    }
  }
  return links;
}

Map* LoopClosing::CorrectLoop(const CommonRegion& region, LoopEvent* event) {
  StopGlobalBundle();
  PauseMapping();
  Map* map = nullptr;
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kLoopCorrection);
    KeyFrame* query = region.query.get();
    map = query->map();
    if (query->IsBad() || map == nullptr || region.matched->IsBad() ||
        region.matched->map() != map) {
      lock.unlock();
      ReleaseMapping();
      return nullptr;
    }
    query->UpdateConnections(lock);
    const std::vector<KeyFrame*> neighbourhood = Neighbourhood(query);

    // Corrected poses: every neighbour keeps its pose relative to the query, i.e. the whole
    // neighbourhood moves by the loop's world correction (world_new_from_world_old).
    LoopCorrection correction;
    correction.current_keyframe = query->id();
    correction.loop_keyframe = region.matched->id();
    const Eigen::Vector3d query_centre_before = query->CameraCenter();
    const bool four_dof = UsesFourDof(*map);
    const auto gravity_before = GravityInCameras(*map);
    Sim3d world_correction =
        region.query_camera_from_world.Inverse() * Sim3d(query->camera_from_world());
    if (four_dof) world_correction = ProjectToYawTranslation(world_correction, query_centre_before);
    for (KeyFrame* kf : neighbourhood) {
      const Sim3d non_corrected(kf->camera_from_world());
      correction.non_corrected_camera_from_world[kf->id()] = non_corrected;
      correction.corrected_camera_from_world[kf->id()] = non_corrected * world_correction.Inverse();
    }
    // Points move with the first neighbour that sees them; then the poses.
    std::vector<MapPoint*> moved;
    for (KeyFrame* kf : neighbourhood) {
      const Sim3d& corrected = correction.corrected_camera_from_world.at(kf->id());
      const Sim3d& non_corrected = correction.non_corrected_camera_from_world.at(kf->id());
      const Sim3d world_correction = corrected.Inverse() * non_corrected;
      for (const auto& mp : kf->map_points()) {
        if (!mp || mp->IsBad() || correction.corrected_points.count(mp->id()) > 0) continue;
        mp->SetPosition(lock, world_correction * mp->position());
        correction.corrected_points[mp->id()] = kf->id();
        moved.push_back(mp.get());
      }
    }
    for (KeyFrame* kf : neighbourhood) {
      kf->SetPose(lock,
                  correction.corrected_camera_from_world.at(kf->id()).ToSE3ScaledTranslation());
    }
    for (MapPoint* mp : moved) mp->UpdateNormalAndDepth(lock);
    event->correction_m = (query->CameraCenter() - query_centre_before).norm();

    correction.loop_connections =
        FuseRegion(lock, region, neighbourhood, correction.corrected_camera_from_world);

    EssentialGraphOptions graph;
    graph.dof = GraphDof(*map);
    graph.num_threads = options_.num_threads;
    const EssentialGraphProblem problem = CollectEssentialGraph(map, correction, graph);
    ApplyEssentialGraph(lock, map, problem, SolveEssentialGraph(problem, graph));
    query->AddLoopEdge(lock, region.matched.get());
    region.matched->AddLoopEdge(lock, query);
    // Tracking predicts from its last keyframe (corrected pose and velocity) next time.
    if (four_dof) map->RecordWorldChange(lock, {});
    PKSLAM_LOG_INFO(
        "loop correction of map {} ({}): yaw {:.4f} rad, largest keyframe tilt change "
        "{:.2e} rad",
        map->id(), four_dof ? "4-DoF" : "6/7-DoF", ClosestYawAngle(world_correction.so3()),
        MaxTiltChange(*map, gravity_before));
  }
  ReleaseMapping();
  return map;
}

Map* LoopClosing::MergeMaps(const CommonRegion& region, LoopEvent* event) {
  StopGlobalBundle();
  PauseMapping();
  Map* merged = nullptr;
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kMergeMaps);
    KeyFrame* query = region.query.get();
    Map* current = query->map();
    merged = region.matched->map();
    if (query->IsBad() || region.matched->IsBad() || current == nullptr || merged == nullptr ||
        current == merged || current != atlas_->current_map()) {
      lock.unlock();
      ReleaseMapping();
      return nullptr;
    }
    // The current map's world in the recognised map's world. Two gravity-aligned worlds
    // differ by yaw + translation only: the alignment keeps both maps' gravity.
    const bool four_dof = UsesFourDof(*current) && UsesFourDof(*merged);
    const Eigen::Vector3d query_centre_before = query->CameraCenter();
    Sim3d merged_from_current =
        region.query_camera_from_world.Inverse() * Sim3d(query->camera_from_world());
    if (four_dof) {
      merged_from_current = ProjectToYawTranslation(merged_from_current, query_centre_before);
    }
    const Sim3d current_from_merged = merged_from_current.Inverse();
    for (const auto& [id, kf] : current->keyframes()) {
      kf->SetPose(lock,
                  (Sim3d(kf->camera_from_world()) * current_from_merged).ToSE3ScaledTranslation());
      kf->mutable_imu(lock).state.velocity_world =
          merged_from_current.scale() *
          (merged_from_current.so3() * kf->imu().state.velocity_world);
    }
    for (const auto& [id, kf] : current->retired_keyframes()) {
      kf->SetPose(lock,
                  (Sim3d(kf->camera_from_world()) * current_from_merged).ToSE3ScaledTranslation());
    }
    for (const auto& [id, mp] : current->map_points()) {
      mp->SetPosition(lock, merged_from_current * mp->position());
    }
    event->correction_m = (query->CameraCenter() - query_centre_before).norm();

    // Ownership moves to the recognised map.
    std::vector<KeyFramePtr> live;
    std::vector<KeyFramePtr> retired;
    std::vector<MapPointPtr> points;
    for (const auto& [id, kf] : current->keyframes()) live.push_back(kf);
    for (const auto& [id, kf] : current->retired_keyframes()) retired.push_back(kf);
    for (const auto& [id, mp] : current->map_points()) points.push_back(mp);
    for (const auto& kf : live) {
      current->TakeKeyFrame(kf.get());
      kf->set_map(merged);
      merged->AddKeyFrame(lock, kf);
    }
    for (const auto& kf : retired) {
      current->TakeKeyFrame(kf.get());
      kf->set_map(merged);
      merged->AddRetiredKeyFrame(lock, kf);
    }
    for (const auto& mp : points) {
      current->TakeMapPoint(mp.get());
      mp->set_map(merged);
      merged->AddMapPoint(lock, mp);
    }
    for (const auto& mp : points) mp->UpdateNormalAndDepth(lock);

    // Re-root the moved spanning tree at the query and hang it from the matched keyframe.
    KeyFrame* new_parent = region.matched.get();
    for (KeyFrame* kf = query; kf != nullptr;) {
      KeyFrame* old_parent = kf->parent();
      if (old_parent != nullptr) old_parent->EraseChild(lock, kf);
      kf->ChangeParent(lock, new_parent);
      new_parent = kf;
      kf = old_parent;
    }

    // Weld: fuse the two sides around the query and optimise the merged essential graph.
    query->UpdateConnections(lock);
    const std::vector<KeyFrame*> neighbourhood = Neighbourhood(query);
    LoopCorrection correction;
    correction.current_keyframe = query->id();
    correction.loop_keyframe = region.matched->id();
    for (KeyFrame* kf : neighbourhood) {
      const Sim3d pose(kf->camera_from_world());
      correction.corrected_camera_from_world[kf->id()] = pose;
      correction.non_corrected_camera_from_world[kf->id()] = pose;
    }
    correction.loop_connections =
        FuseRegion(lock, region, neighbourhood, correction.corrected_camera_from_world);
    EssentialGraphOptions graph;
    graph.dof = four_dof ? PoseGraphDof::kYawTranslation
                         : (options_.verifier.fix_scale ? PoseGraphDof::kSE3 : PoseGraphDof::kSim3);
    graph.num_threads = options_.num_threads;
    const EssentialGraphProblem problem = CollectEssentialGraph(merged, correction, graph);
    ApplyEssentialGraph(lock, merged, problem, SolveEssentialGraph(problem, graph));
    query->AddLoopEdge(lock, region.matched.get());
    region.matched->AddLoopEdge(lock, query);

    merged->mutable_imu_status(lock).imu_initialized =
        merged->imu_status().imu_initialized && current->imu_status().imu_initialized;
    merged->RecordWorldChange(lock, {});
    atlas_->SetCurrentMap(lock, merged);
    atlas_->RemoveMap(lock, current);
    merged->IncreaseChangeIndex(lock);
  }
  ReleaseMapping();
  return merged;
}

}  // namespace pkslam
