// Tracking's cursor into a map's world-change log (map_model/world_change.h): which changes
// local mapping and loop closing made to the current map since tracking last looked, reduced
// to what tracking must do about them. Tracking thread; Follow reads the map under the Atlas
// lock (shared).
#pragma once

#include <optional>

#include "map_model/world_change.h"

namespace pkslam {

class Map;

// What changed since the last look.
struct WorldChangesSeen {
  // The first look at this map (a new, reset or merged-into map): nothing to carry across, but
  // what tracking derived from the previous map (its last frame's inertial information) is void.
  bool new_map = false;
  // Entries were added to the log: the keyframes' states were re-estimated.
  bool changed = false;
  // The transforms among them; the one transform when there was exactly one (a frame tracked
  // before it can be carried across exactly; across several it cannot, they were not observed
  // one by one).
  int transforms = 0;
  std::optional<WorldChange> single_transform;
  // The map's scale changed by this factor (monocular-inertial initialisation): what tracking
  // keeps relative to keyframes scales with it.
  std::optional<double> scale_ratio;

  bool ForgetsLastFrame() const { return new_map || changed; }
};

class WorldChangeCursor {
 public:
  // Moves the cursor to the end of `map`'s log and reports what it passed. Atlas lock held.
  WorldChangesSeen Follow(const Map& map);

 private:
  const Map* map_ = nullptr;
  int seen_changes_ = 0;
  double seen_scale_ = 1.0;
};

}  // namespace pkslam
