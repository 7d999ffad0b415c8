#include "mapping/neighbour_fusion.h"

#include <unordered_set>
#include <vector>

#include "core/util/error.h"
#include "core/util/work_meter.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"

namespace pkslam {

int FuseWithNeighbours(const MapWriteLock& lock, KeyFrame* keyframe,
                       const NeighbourFusionOptions& options) {
  RequireWriteLock(lock, "FuseWithNeighbours");
  if (keyframe->IsBad() || keyframe->map() == nullptr) return 0;
  std::vector<KeyFrame*> targets;
  std::unordered_set<KeyFrameId> in_targets{keyframe->id()};
  for (KeyFrame* neighbour : keyframe->BestCovisibles(options.first_ring)) {
    if (neighbour->IsBad() || !in_targets.insert(neighbour->id()).second) continue;
    targets.push_back(neighbour);
  }
  const std::size_t first_ring = targets.size();
  for (std::size_t i = 0; i < first_ring; ++i) {
    for (KeyFrame* second : targets[i]->BestCovisibles(options.second_ring)) {
      if (second->IsBad() || !in_targets.insert(second->id()).second) continue;
      targets.push_back(second);
    }
  }
  const OrbMatcher matcher;
  // Our points into the neighbours...
  const std::vector<MapPointPtr> ours = keyframe->GoodMapPoints();
  for (KeyFrame* target : targets) matcher.Fuse(lock, target, ours);
  // ...and the neighbours' points into us.
  std::vector<MapPointPtr> candidates;
  std::unordered_set<MapPointId> seen;
  for (const auto& mp : keyframe->GoodMapPoints()) seen.insert(mp->id());
  for (KeyFrame* target : targets) {
    for (const auto& mp : target->map_points()) {
      if (!mp || mp->IsBad() || !seen.insert(mp->id()).second) continue;
      candidates.push_back(mp);
    }
  }
  matcher.Fuse(lock, keyframe, candidates);
  if (options.work != nullptr) {
    options.work->Add(WorkKind::kFuseProjection,
                      static_cast<std::int64_t>(ours.size() * targets.size() + candidates.size()));
  }
  for (const auto& mp : keyframe->GoodMapPoints()) {
    mp->ComputeDistinctiveDescriptor(lock);
    mp->UpdateNormalAndDepth(lock);
  }
  keyframe->UpdateConnections(lock);
  return static_cast<int>(targets.size());
}

}  // namespace pkslam
