#include "tracking/world_change_cursor.h"

#include "map_model/map.h"

namespace pkslam {

WorldChangesSeen WorldChangeCursor::Follow(const Map& map) {
  WorldChangesSeen seen;
  const int changes = map.NumWorldChanges();
  if (&map != map_) {
    map_ = &map;
    seen_changes_ = changes;
    seen_scale_ = map.applied_scale();
    seen.new_map = true;
    return seen;
  }
  if (changes == seen_changes_) return seen;
  seen.changed = true;
  for (int i = seen_changes_; i < changes; ++i) {
    if (map.world_change(i).kind == WorldChange::Kind::kTransform) {
      ++seen.transforms;
      seen.single_transform = map.world_change(i);
    }
  }
  if (seen.transforms != 1) seen.single_transform.reset();
  seen_changes_ = changes;
  if (map.applied_scale() != seen_scale_) {
    seen.scale_ratio = map.applied_scale() / seen_scale_;
    seen_scale_ = map.applied_scale();
  }
  return seen;
}

}  // namespace pkslam
