#include "mapping/keyframe_admission.h"

#include "core/util/error.h"
#include "map_model/atlas.h"
#include "map_model/keyframe.h"
#include "map_model/keyframe_database.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"

namespace pkslam {

std::vector<MapPointPtr> AdmitKeyFrame(const MapWriteLock& lock, Atlas* atlas, KeyFrame* keyframe) {
  RequireWriteLock(lock, "AdmitKeyFrame");
  std::vector<MapPointPtr> created;
  if (keyframe->IsBad() || keyframe->map() == nullptr) return created;
  const auto& points = keyframe->map_points();
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const MapPointPtr mp = points[i];
    if (!mp || mp->IsBad()) continue;
    if (!mp->IsInKeyFrame(keyframe)) {
      // A point tracked by the frame: the keyframe becomes one of its observers.
      mp->AddObservation(lock, keyframe, i);
      mp->UpdateNormalAndDepth(lock);
      mp->ComputeDistinctiveDescriptor(lock);
    } else {
      created.push_back(mp);
    }
  }
  keyframe->UpdateConnections(lock);
  // Findable by relocalisation and place recognition from now on.
  if (KeyFrameDatabase* database = atlas->database()) database->Add(lock, keyframe);
  return created;
}

}  // namespace pkslam
