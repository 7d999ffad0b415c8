#include "mapping/recent_points.h"

#include "core/util/error.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"

namespace pkslam {

int RecentPoints::Cull(const MapWriteLock& lock, KeyFrameId newest, const RecentPointRule& rule) {
  RequireWriteLock(lock, "RecentPoints::Cull");
  int culled = 0;
  std::erase_if(points_, [&](const MapPointPtr& mp) {
    if (mp->IsBad()) return true;
    const KeyFrameId age = newest - mp->first_keyframe_id();
    if (mp->FoundRatio() < rule.min_found_ratio) {
      mp->SetBad(lock);
      ++culled;
      return true;
    }
    if (age >= 2 && mp->NumObservations() <= rule.min_observations) {
      mp->SetBad(lock);
      ++culled;
      return true;
    }
    return age >= 3;  // survived its probation
  });
  return culled;
}

}  // namespace pkslam
