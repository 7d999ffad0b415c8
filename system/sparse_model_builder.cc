#include "system/sparse_model_builder.h"

#include <mutex>
#include <set>
#include <shared_mutex>

#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"

namespace pkslam {

SparseModel BuildSparseModel(const SlamSystem& system) {
  SparseModel model;
  const CameraRig& rig = system.rig();
  model.camera = {rig.camera.width(), rig.camera.height(), rig.camera.fx(), rig.camera.fy(),
                  rig.camera.cx(),    rig.camera.cy(),     rig.bf};

  auto lock = MapReader(system.atlas()).Lock();
  const Map* map = system.LargestMap();
  if (map == nullptr) return model;
  // A keypoint refers to a point only when the link is mutual (the point lists that
  // observation) and the point is live in this map, so the model is consistent by
  // construction.
  auto live_point = [map](const MapPointPtr& mp) {
    return mp != nullptr && !mp->IsBad() && mp->map() == map &&
           map->map_points().count(mp->id()) > 0;
  };
  std::set<KeyFrameId> keyframe_ids;
  for (const auto& [id, kf] : map->keyframes()) {
    if (!kf->IsBad()) keyframe_ids.insert(id);
  }
  for (const auto& [id, kf] : map->keyframes()) {
    if (kf->IsBad()) continue;
    SparseKeyframe out;
    out.id = id;
    out.t_ns = kf->t_ns();
    out.camera_from_world = kf->camera_from_world();
    const auto& keypoints = kf->keypoints_undistorted();
    out.keypoints.resize(keypoints.size());
    for (std::size_t i = 0; i < keypoints.size(); ++i) {
      SparseKeypoint& k = out.keypoints[i];
      k.u = keypoints[i].pt.x;
      k.v = keypoints[i].pt.y;
      k.octave = keypoints[i].octave;
      const MapPointPtr& mp = kf->map_point(static_cast<int>(i));
      if (live_point(mp) && mp->IndexInKeyFrame(kf.get()) == static_cast<int>(i)) {
        k.point_id = mp->id();
      }
    }
    model.keyframes.push_back(std::move(out));
  }
  for (const auto& [id, mp] : map->map_points()) {
    if (!live_point(mp)) continue;
    SparsePoint p;
    p.id = id;
    p.position_world = mp->position();
    for (const auto& [kf_id, obs] : mp->observations()) {
      if (keyframe_ids.count(kf_id) == 0 || obs.index < 0 || obs.index >= obs.keyframe->size() ||
          obs.keyframe->map_point(obs.index).get() != mp.get()) {
        continue;
      }
      p.observations.emplace_back(kf_id, obs.index);
    }
    model.points.push_back(std::move(p));
  }
  return model;
}

}  // namespace pkslam
