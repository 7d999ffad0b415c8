#include "tracking/keyframe_points.h"

#include <algorithm>
#include <memory>
#include <utility>
#include <vector>

#include "core/bow/vocabulary.h"
#include "core/util/error.h"
#include "map_model/atlas.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"

namespace pkslam {

int AddClosePoints(const MapWriteLock& lock, Atlas* atlas, KeyFrame* keyframe,
                   const ClosePointRule& rule, Frame* frame) {
  RequireWriteLock(lock, "AddClosePoints");
  Map* map = keyframe->map();
  std::vector<std::pair<float, int>> by_depth;
  for (int i = 0; i < frame->size(); ++i) {
    if (frame->depth()[i] > 0) by_depth.emplace_back(frame->depth()[i], i);
  }
  std::sort(by_depth.begin(), by_depth.end());
  int count = 0;
  int created = 0;
  for (const auto& [z, i] : by_depth) {
    auto& slot = frame->map_points[i];
    if (!slot || slot->NumObservations() < 1) {
      slot.reset();
      const auto p = frame->UnprojectStereo(i);
      slot = map->CreateMapPoint(lock, atlas->NextMapPointId(), *p, keyframe, {{keyframe, i}});
      ++created;
    }
    ++count;
    if (z > rule.th_depth && count > rule.min_close) break;
  }
  return created;
}

KeyFramePtr CreateKeyFrame(const MapWriteLock& lock, Atlas* atlas, const Vocabulary& vocabulary,
                           const AttachKeyFrame& attach, KeyFrame* previous,
                           const std::optional<ClosePointRule>& close_points, Frame* frame) {
  RequireWriteLock(lock, "CreateKeyFrame");
  Map* map = atlas->current_map();
  frame->ComputeBoW(vocabulary);
  auto keyframe = std::make_shared<KeyFrame>(atlas->NextKeyFrameId(), *frame, map);
  map->AddKeyFrame(lock, keyframe);
  attach(lock, keyframe.get(), previous, *frame);
  if (close_points) AddClosePoints(lock, atlas, keyframe.get(), *close_points, frame);
  return keyframe;
}

}  // namespace pkslam
