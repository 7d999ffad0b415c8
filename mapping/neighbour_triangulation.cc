#include "mapping/neighbour_triangulation.h"

#include <cstdint>
#include <memory>
#include <unordered_set>

#include "core/util/error.h"
#include "core/util/work_meter.h"
#include "map_model/atlas.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"

namespace pkslam {

std::vector<TriangulatedPoint> TriangulateWithNeighbours(
    const KeyFrame& keyframe, const NeighbourTriangulationOptions& options) {
  std::vector<TriangulatedPoint> found;
  const std::vector<KeyFrame*> neighbours = keyframe.BestCovisibles(options.neighbours);
  const OrbMatcher matcher(0.6, false);
  std::unordered_set<int> claimed;  // keypoints of `keyframe` already given a point
  for (std::size_t n = 0; n < neighbours.size(); ++n) {
    if (n > 0 && options.stop && options.stop()) break;
    KeyFrame* other = neighbours[n];
    if (!HasTriangulationBaseline(keyframe, *other, options.monocular)) continue;
    if (options.work != nullptr) {
      options.work->Add(WorkKind::kTriangulationPair,
                        static_cast<std::int64_t>(keyframe.keypoints_undistorted().size() +
                                                  other->keypoints_undistorted().size()));
    }
    const auto pairs = matcher.SearchForTriangulation(keyframe, *other);
    for (const auto& [i1, i2] : pairs) {
      if (claimed.count(i1) > 0) continue;
      if (auto p = TriangulatePair(keyframe, i1, *other, i2, options.monocular)) {
        claimed.insert(i1);
        found.push_back({*p, other, i1, i2});
      }
    }
  }
  return found;
}

std::vector<MapPointPtr> AddTriangulatedPoints(const MapWriteLock& lock, Atlas* atlas,
                                               KeyFrame* keyframe,
                                               const std::vector<TriangulatedPoint>& found) {
  RequireWriteLock(lock, "AddTriangulatedPoints");
  std::vector<MapPointPtr> added;
  Map* map = keyframe->map();
  if (keyframe->IsBad() || map == nullptr) return added;
  for (const auto& c : found) {
    // Tracking never fills existing keyframes' slots and local mapping is the only other
    // writer, but a neighbour may have been retired by loop closing's fusion meanwhile.
    if (c.other->IsBad() || keyframe->map_point(c.index1) || c.other->map_point(c.index2)) {
      continue;
    }
    added.push_back(map->CreateMapPoint(lock, atlas->NextMapPointId(), c.position, keyframe,
                                        {{keyframe, c.index1}, {c.other, c.index2}}));
  }
  return added;
}

}  // namespace pkslam
