#include "map_model/estimation/gravity_refinement_collect.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/util/error.h"
#include "estimators/inertial/gravity_gauge.h"
#include "map_model/estimation/global_bundle_merge.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"

namespace pkslam {

std::optional<GravityRefinementProblem> CollectGravityRefinement(
    KeyFrame* keyframe, const GravityRefinementRule& rule, const InertialBundleOptions& options) {
  if (keyframe->IsBad() || keyframe->map() == nullptr) return std::nullopt;
  const Map* map = keyframe->map();
  const std::vector<KeyFrame*> chain = InertialChain::EndingAt(keyframe, 0);
  if (chain.size() < 2 || static_cast<int>(chain.size()) > rule.max_keyframes) {
    return std::nullopt;
  }
  std::vector<SO3d> orientations;
  orientations.reserve(chain.size());
  for (const KeyFrame* k : chain) orientations.push_back(k->world_from_body().so3());
  GravityRefinementProblem problem;
  problem.observability = TiltObservability(orientations);
  const double due = std::max(rule.min_observability,
                              map->imu_status().gravity_refinement_observability + rule.step);
  if (problem.observability < due) return std::nullopt;
  problem.bundle = CollectFullInertialBundle(keyframe, options, /*free_tilt=*/true);
  problem.change_index = map->change_index();
  return problem;
}

double ApplyGravityRefinement(const MapWriteLock& lock, Map* map, const KeyFrame& keyframe,
                              const GravityRefinementProblem& problem,
                              const InertialBundleResult& result) {
  RequireWriteLock(lock, "ApplyGravityRefinement");
  const InertialBundleProblem& bundle = problem.bundle;
  // Live or retired: the problem's first keyframe measures the tilt change either way.
  const KeyFramePtr first_kf = map->FindKeyFrame(bundle.visual.keyframes.front().keyframe_id);
  PKSLAM_CHECK(first_kf != nullptr, "gravity refinement: keyframe {} left map {}",
               bundle.visual.keyframes.front().keyframe_id, map->id());
  const KeyFrame& first = *first_kf;
  const Eigen::Vector3d up_before = first.camera_from_world().so3() * Eigen::Vector3d::UnitZ();
  MergeGlobalBundle(
      lock, map, bundle.visual, [&] { ApplyInertialBundle(lock, map, bundle, result); },
      /*apply_sets_velocities=*/true);
  const Eigen::Vector3d up_after = first.camera_from_world().so3() * Eigen::Vector3d::UnitZ();
  // Keyframes tracked while the BA ran continue from the newest estimate.
  for (const auto& [id, other] : map->keyframes()) {
    if (other->id() > keyframe.id() && !other->IsBad()) {
      other->mutable_imu(lock).state.bias = keyframe.imu().state.bias;
    }
  }
  map->mutable_imu_status(lock).gravity_refinement_observability = problem.observability;
  map->RecordWorldChange(lock, {});
  return std::atan2(up_after.cross(up_before).norm(), up_after.dot(up_before));
}

}  // namespace pkslam
