#include "mapping/keyframe_culling.h"

#include <vector>

#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"

namespace pkslam {

bool IsRedundant(const KeyFrame& candidate, const KeyFrameRedundancy& rule) {
  const auto& kps = candidate.keypoints_undistorted();
  int points = 0;
  int redundant = 0;
  const auto& slots = candidate.map_points();
  for (int i = 0; i < static_cast<int>(slots.size()); ++i) {
    const auto& mp = slots[i];
    if (!mp || mp->IsBad()) continue;
    if (rule.max_depth >= 0) {
      const float depth = candidate.depth()[i];
      if (depth < 0 || depth > rule.max_depth) continue;
    }
    ++points;
    if (mp->NumObservations() <= rule.observers) continue;
    const int level = kps[i].octave;
    int seen_by = 0;
    for (const auto& [id, obs] : mp->observations()) {
      if (obs.keyframe == &candidate) continue;
      if (obs.keyframe->keypoints_undistorted()[obs.index].octave <= level + 1) {
        if (++seen_by >= rule.observers) break;
      }
    }
    if (seen_by >= rule.observers) ++redundant;
  }
  return points > 0 && redundant > rule.share * points;
}

int CullRedundantKeyFrames(const MapWriteLock& lock, KeyFrame* newest,
                           const KeyFrameCullingInput& input) {
  const KeyFrame* origin = newest->map()->origin();
  const InertialCullingOptions* inertial = input.inertial;
  InertialCullingContext context;
  if (inertial != nullptr) {
    RepairInertialChain(lock, newest, 2 * inertial->window);
    context = MakeInertialCullingContext(*newest, *inertial);
  }
  int culled = 0;
  int examined = 0;
  for (KeyFrame* candidate : std::vector<KeyFrame*>(newest->CovisiblesByWeight())) {
    if (candidate == origin || candidate->IsBad()) continue;
    if (++examined > 100) break;
    if (inertial != nullptr && examined > 20 && input.abort != nullptr && input.abort->load()) {
      break;
    }
    if (inertial != nullptr && !InertialCullingAllowed(*candidate, context, *inertial)) continue;
    if (!IsRedundant(*candidate, input.redundancy)) continue;
    candidate->SetBad(lock);
    if (!candidate->IsBad()) continue;  // protected by loop closing for now
    if (inertial != nullptr) candidate->map()->inertial_chain().SpliceOut(lock, candidate);
    ++culled;
  }
  return culled;
}

}  // namespace pkslam
