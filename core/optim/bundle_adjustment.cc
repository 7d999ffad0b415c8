// Collect and Apply phases of bundle adjustment (the map-facing parts); the solver is in
// bundle_solve.cc.
#include "core/optim/bundle_adjustment.h"

#include <algorithm>
#include <unordered_map>
#include <unordered_set>

#include "core/map/keyframe.h"
#include "core/map/map.h"
#include "core/map/map_point.h"
#include "core/util/error.h"

namespace pkslam {
namespace {

// Keyframe -> index into problem.keyframes. Only looked up, never iterated (determinism).
using KeyFrameIndex = std::unordered_map<const KeyFrame*, int>;

void SetIntrinsics(const CameraRig& rig, BundleProblem* problem) {
  problem->fx = rig.fx;
  problem->fy = rig.fy;
  problem->cx = rig.cx;
  problem->cy = rig.cy;
  problem->bf = rig.bf;
}

void AddKeyFrame(const KeyFramePtr& kf, bool fixed, BundleProblem* problem, KeyFrameIndex* index) {
  (*index)[kf.get()] = static_cast<int>(problem->keyframes.size());
  problem->keyframes.push_back({kf, kf->camera_from_world(), fixed});
}

// Adds the point and its observations by keyframes in `index` (in keyframe-id order). Returns
// false (and adds nothing) if no such keyframe observes it.
bool AddPoint(const MapPointPtr& point, const KeyFrameIndex& index, BundleProblem* problem) {
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
  if (any) problem->points.push_back({point, point->position()});
  return any;
}

// Every problem needs a gauge: if nothing is fixed, fix the oldest keyframe.
void EnsureFixedKeyFrame(BundleProblem* problem) {
  if (problem->keyframes.empty()) return;
  for (const auto& k : problem->keyframes) {
    if (k.fixed) return;
  }
  auto oldest = std::min_element(
      problem->keyframes.begin(), problem->keyframes.end(),
      [](const auto& a, const auto& b) { return a.keyframe->id() < b.keyframe->id(); });
  oldest->fixed = true;
}

}  // namespace

void BundleAdjustmentOptions::Check() const {
  PKSLAM_CHECK_OPTION(iterations_first >= 1, "ba.iterations_first", "{}", iterations_first);
  PKSLAM_CHECK_OPTION(iterations_second >= 0, "ba.iterations_second", "{}", iterations_second);
  PKSLAM_CHECK_OPTION(chi2_mono > 0, "ba.chi2_mono", "{}", chi2_mono);
  PKSLAM_CHECK_OPTION(chi2_stereo > 0, "ba.chi2_stereo", "{}", chi2_stereo);
  PKSLAM_CHECK_OPTION(num_threads >= 1, "ba.num_threads", "{}", num_threads);
  PKSLAM_CHECK_OPTION(max_local_keyframes >= 0, "ba.max_local_keyframes", "{}",
                      max_local_keyframes);
}

BundleProblem CollectLocalBundle(KeyFrame* keyframe, const BundleAdjustmentOptions& options) {
  options.Check();
  BundleProblem problem;
  if (keyframe == nullptr || keyframe->IsBad()) return problem;
  const Map* map = keyframe->map();
  PKSLAM_CHECK(map != nullptr, "keyframe {} has no map", keyframe->id());
  const KeyFramePtr self = map->Share(keyframe);
  PKSLAM_CHECK(self != nullptr, "keyframe {} is not live in its map", keyframe->id());
  SetIntrinsics(keyframe->rig(), &problem);

  // Local keyframes: the keyframe and its covisibles by decreasing weight. The map's origin
  // stays fixed even when it is local (it anchors the map's frame).
  KeyFrameIndex index;
  AddKeyFrame(self, keyframe == map->origin(), &problem, &index);
  for (KeyFrame* kf : keyframe->CovisiblesByWeight()) {
    if (options.max_local_keyframes > 0 &&
        static_cast<int>(problem.keyframes.size()) >= options.max_local_keyframes) {
      break;
    }
    if (kf->IsBad() || kf->map() != map) continue;
    const KeyFramePtr shared = map->Share(kf);
    if (shared) AddKeyFrame(shared, kf == map->origin(), &problem, &index);
  }

  // Local points: every good point of a local keyframe, in first-seen order.
  std::vector<MapPointPtr> points;
  std::unordered_set<const MapPoint*> seen;
  for (const auto& k : problem.keyframes) {
    for (const MapPointPtr& point : k.keyframe->map_points()) {
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
  for (KeyFrame* kf : fixed) {
    const KeyFramePtr shared = map->Share(kf);
    if (shared) AddKeyFrame(shared, true, &problem, &index);
  }
  EnsureFixedKeyFrame(&problem);

  for (const MapPointPtr& point : points) AddPoint(point, index, &problem);
  return problem;
}

BundleProblem CollectGlobalBundle(const Map& map) {
  BundleProblem problem;
  KeyFrameIndex index;
  for (const auto& [id, kf] : map.keyframes()) {
    if (kf->IsBad()) continue;
    if (problem.keyframes.empty()) SetIntrinsics(kf->rig(), &problem);
    AddKeyFrame(kf, kf.get() == map.origin(), &problem, &index);
  }
  EnsureFixedKeyFrame(&problem);
  for (const auto& [id, point] : map.map_points()) {
    if (!point->IsBad()) AddPoint(point, index, &problem);
  }
  return problem;
}

void ApplyBundle(const BundleProblem& problem, const BundleResult& result) {
  PKSLAM_CHECK(result.camera_from_world.size() == problem.keyframes.size() &&
                   result.points_world.size() == problem.points.size(),
               "result ({} poses, {} points) does not match the problem ({}, {})",
               result.camera_from_world.size(), result.points_world.size(),
               problem.keyframes.size(), problem.points.size());
  // The map may have changed between Collect and Apply (culling, fusion): every link is
  // re-validated before it is touched.
  for (const int o : result.outlier_observations) {
    const BundleProblem::ObservationState& obs = problem.observations.at(o);
    KeyFrame* kf = problem.keyframes[obs.keyframe_index].keyframe.get();
    MapPoint* point = problem.points[obs.point_index].point.get();
    if (kf->IsBad() || point->IsBad()) continue;
    if (point->IndexInKeyFrame(kf) != obs.keypoint_index) continue;
    if (kf->map_point(obs.keypoint_index).get() == point) {
      kf->EraseMapPointMatch(obs.keypoint_index);
    }
    point->EraseObservation(kf);  // may retire the point (too few observations left)
  }
  for (std::size_t i = 0; i < problem.keyframes.size(); ++i) {
    const auto& k = problem.keyframes[i];
    if (!k.fixed && !k.keyframe->IsBad()) k.keyframe->SetPose(result.camera_from_world[i]);
  }
  for (std::size_t i = 0; i < problem.points.size(); ++i) {
    MapPoint* point = problem.points[i].point.get();
    if (point->IsBad()) continue;
    point->SetPosition(result.points_world[i]);
    point->UpdateNormalAndDepth();
  }
}

}  // namespace pkslam
