// Collect and Apply phases of bundle adjustment (the map-facing parts); the solver is
// estimators/optim/bundle_solve.cc.
#include "map_model/estimation/bundle_collect.h"

#include <algorithm>
#include <unordered_map>
#include <unordered_set>

#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_point.h"

namespace pkslam {
namespace {

void SetIntrinsics(const CameraRig& rig, BundleProblem* problem) {
  problem->fx = rig.fx;
  problem->fy = rig.fy;
  problem->cx = rig.cx;
  problem->cy = rig.cy;
  problem->bf = rig.bf;
}

void AddKeyFrame(const KeyFrame* kf, bool fixed, BundleProblem* problem,
                 BundleKeyFrameIndex* index) {
  (*index)[kf] = static_cast<int>(problem->keyframes.size());
  problem->keyframes.push_back({kf->id(), kf->camera_from_world(), fixed});
}

// Every problem needs a gauge: if nothing is fixed, fix the oldest keyframe.
void EnsureFixedKeyFrame(BundleProblem* problem) {
  if (problem->keyframes.empty()) return;
  for (const auto& k : problem->keyframes) {
    if (k.fixed) return;
  }
  auto oldest =
      std::min_element(problem->keyframes.begin(), problem->keyframes.end(),
                       [](const auto& a, const auto& b) { return a.keyframe_id < b.keyframe_id; });
  oldest->fixed = true;
}

}  // namespace

bool AddBundlePoint(const MapPointPtr& point, const BundleKeyFrameIndex& index,
                    BundleProblem* problem) {
  const int point_index = static_cast<int>(problem->points.size());
  bool any = false;
  for (const auto& [id, obs] : point->observations()) {
    const auto it = index.find(obs.keyframe);
    if (it == index.end()) continue;
    const KeyFrame& kf = *obs.keyframe;
    const cv::KeyPoint& kp = kf.keypoints_undistorted()[obs.index];
    const auto& inv_sigma2 = kf.rig().pyramid.inv_sigma2;
    PKSLAM_CHECK(kp.octave >= 0 && kp.octave < static_cast<int>(inv_sigma2.size()),
                 "keyframe {} keypoint {} has octave {}", kf.id(), obs.index, kp.octave);
    const double u_right = kf.right_u().empty() ? -1.0 : kf.right_u()[obs.index];
    problem->observations.push_back({it->second, point_index, obs.index,
                                     Eigen::Vector2d(kp.pt.x, kp.pt.y),
                                     u_right >= 0 ? u_right : -1.0, inv_sigma2[kp.octave],
                                     u_right >= 0 ? kf.DisparityInformation(obs.index) : 0.0});
    any = true;
  }
  if (any) problem->points.push_back({point->id(), point->position()});
  return any;
}

BundleProblem CollectLocalBundle(const MapLock& lock, KeyFrame* keyframe,
                                 const BundleAdjustmentOptions& options) {
  RequireMapLock(lock, "CollectLocalBundle");
  options.Check();
  BundleProblem problem;
  if (keyframe == nullptr || keyframe->IsBad()) return problem;
  const Map* map = keyframe->map();
  PKSLAM_CHECK(map != nullptr, "keyframe {} has no map", keyframe->id());
  PKSLAM_CHECK(map->Share(keyframe) != nullptr, "keyframe {} is not live in its map",
               keyframe->id());
  SetIntrinsics(keyframe->rig(), &problem);
  problem.map_id = map->id();

  // Local keyframes: the keyframe and its covisibles by decreasing weight. The map's origin
  // stays fixed even when it is local (it anchors the map's frame).
  BundleKeyFrameIndex index;
  std::vector<const KeyFrame*> local{keyframe};
  for (KeyFrame* kf : keyframe->CovisiblesByWeight()) {
    if (options.max_local_keyframes > 0 &&
        static_cast<int>(local.size()) >= options.max_local_keyframes) {
      break;
    }
    if (!kf->IsBad() && kf->map() == map && map->Share(kf) != nullptr) local.push_back(kf);
  }
  for (const KeyFrame* kf : local) AddKeyFrame(kf, kf == map->origin(), &problem, &index);

  // Local points: every good point of a local keyframe, in first-seen order.
  std::vector<MapPointPtr> points;
  std::unordered_set<const MapPoint*> seen;
  for (const KeyFrame* kf : local) {
    for (const MapPointPtr& point : kf->map_points()) {
      if (point && !point->IsBad() && point->map() == map && seen.insert(point.get()).second) {
        points.push_back(point);
      }
    }
  }

  // Fixed keyframes: other live keyframes of the map observing local points, by id.
  std::vector<KeyFrame*> fixed;
  std::unordered_set<const KeyFrame*> fixed_seen;
  for (const MapPointPtr& point : points) {
    for (const auto& [id, obs] : point->observations()) {
      KeyFrame* kf = obs.keyframe;
      if (index.count(kf) > 0 || kf->IsBad() || kf->map() != map) continue;
      if (fixed_seen.insert(kf).second) fixed.push_back(kf);
    }
  }
  std::sort(fixed.begin(), fixed.end(),
            [](const KeyFrame* a, const KeyFrame* b) { return a->id() < b->id(); });
  for (const KeyFrame* kf : fixed) {
    if (map->Share(kf) != nullptr) AddKeyFrame(kf, true, &problem, &index);
  }
  EnsureFixedKeyFrame(&problem);

  for (const MapPointPtr& point : points) AddBundlePoint(point, index, &problem);
  return problem;
}

BundleProblem CollectGlobalBundle(const MapLock& lock, const Map& map) {
  RequireMapLock(lock, "CollectGlobalBundle");
  BundleProblem problem;
  problem.map_id = map.id();
  BundleKeyFrameIndex index;
  for (const auto& [id, kf] : map.keyframes()) {
    if (kf->IsBad()) continue;
    if (problem.keyframes.empty()) SetIntrinsics(kf->rig(), &problem);
    AddKeyFrame(kf.get(), kf.get() == map.origin(), &problem, &index);
  }
  EnsureFixedKeyFrame(&problem);
  for (const auto& [id, point] : map.map_points()) {
    if (!point->IsBad()) AddBundlePoint(point, index, &problem);
  }
  return problem;
}

void ApplyBundle(const MapWriteLock& lock, Map* map, const BundleProblem& problem,
                 const BundleResult& result) {
  RequireWriteLock(lock, "ApplyBundle");
  PKSLAM_CHECK(map != nullptr, "ApplyBundle without a map");
  PKSLAM_CHECK(problem.map_id == kInvalidId || problem.map_id == map->id(),
               "bundle problem of map {} applied to map {}", problem.map_id, map->id());
  PKSLAM_CHECK(result.camera_from_world.size() == problem.keyframes.size() &&
                   result.points_world.size() == problem.points.size(),
               "result ({} poses, {} points) does not match the problem ({}, {})",
               result.camera_from_world.size(), result.points_world.size(),
               problem.keyframes.size(), problem.points.size());
  // The map may have changed between Collect and Apply (culling, fusion, a merge): every object
  // is looked up again and every link re-validated before it is touched. Shared pointers keep
  // the points alive that the outlier loop retires (the map lets go of them at once).
  std::vector<KeyFramePtr> keyframes(problem.keyframes.size());
  for (std::size_t i = 0; i < keyframes.size(); ++i) {
    keyframes[i] = map->KeyFrameById(problem.keyframes[i].keyframe_id);
  }
  std::vector<MapPointPtr> points(problem.points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    points[i] = map->MapPointById(problem.points[i].point_id);
  }
  for (const int o : result.outlier_observations) {
    const BundleProblem::ObservationState& obs = problem.observations.at(o);
    KeyFrame* kf = keyframes[static_cast<std::size_t>(obs.keyframe_index)].get();
    MapPoint* point = points[static_cast<std::size_t>(obs.point_index)].get();
    if (kf == nullptr || point == nullptr || kf->IsBad() || point->IsBad()) continue;
    if (point->IndexInKeyFrame(kf) != obs.keypoint_index) continue;
    if (kf->map_point(obs.keypoint_index).get() == point) {
      kf->EraseMapPointMatch(lock, obs.keypoint_index);
    }
    point->EraseObservation(lock, kf);  // may retire the point (too few observations left)
  }
  for (std::size_t i = 0; i < problem.keyframes.size(); ++i) {
    KeyFrame* kf = keyframes[i].get();
    if (!problem.keyframes[i].fixed && kf != nullptr && !kf->IsBad()) {
      kf->SetPose(lock, result.camera_from_world[i]);
    }
  }
  for (std::size_t i = 0; i < problem.points.size(); ++i) {
    MapPoint* point = points[i].get();
    if (point == nullptr || point->IsBad()) continue;
    point->SetPosition(lock, result.points_world[i]);
    point->UpdateNormalAndDepth(lock);
  }
}

}  // namespace pkslam
