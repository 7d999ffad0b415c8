// The temporal keyframe chain of an inertial map, and the only code that changes it.
//
// Invariant (kept by every operation here; the first two checked by InertialChain::Check):
//   - k->imu().next()->imu().previous() == k and k->imu().previous()->imu().next() == k where set;
//   - linked keyframes belong to the same map;
//   - k->imu().from_previous, when set on a linked keyframe, spans previous->t_ns() .. k->t_ns()
//     (on the IMU clock: each stamp shifted by its keyframe's time offset);
//   - a keyframe spliced out has neither links, preintegration nor marginalisation prior.
// Keyframes appended by tracking (kInsertKeyFrame, kInitialise) are linked to the newest
// keyframe of the chain; local mapping splices culled ones out (kCullKeyFrames); map files
// restore the links as written (map_model/storage, before the Atlas is shared).
//
// Every change takes the Atlas's exclusive lock as a parameter (map_editor.h), so the compiler
// checks what a comment used to ask for; reads need the shared lock.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/imu/imu_types.h"
#include "map_model/map_ids.h"

namespace pkslam {

class Map;
class MapWriteLock;

// Owned by its Map (Map::inertial_chain()); it holds no keyframes itself: the links live in
// each keyframe's KeyFrameImu, which only this class may set.
class InertialChain {
 public:
  explicit InertialChain(const Map* map) : map_(map) {}
  InertialChain(const InertialChain&) = delete;
  InertialChain& operator=(const InertialChain&) = delete;

  // Links `keyframe` after `previous` with the preintegration between them (linearised at
  // `previous`'s bias; nothing when the IMU has a gap there: linked, but no inertial factor).
  // Both are keyframes of this map; `previous` is the chain's newest.
  void Append(const MapWriteLock& lock, KeyFrame* previous, KeyFrame* keyframe,
              std::optional<PreintegratedImu> from_previous) const;

  // Takes `keyframe` out of the chain (it is being retired). Its successor's preintegration
  // absorbs its interval, re-linearised at the predecessor's bias; without both intervals the
  // chain is cut there instead. The keyframe's marginalisation prior goes with it.
  void SpliceOut(const MapWriteLock& lock, KeyFrame* keyframe) const;

  // The chain ending at `newest` (oldest first), at most `max_length` keyframes (0: all),
  // stopping at a retired keyframe, one of another map or one without a preintegration to its
  // predecessor. Empty for a retired `newest`. Atlas mutex held (shared).
  static std::vector<KeyFrame*> EndingAt(KeyFrame* newest, int max_length);

  // A broken invariant at a keyframe of this map (live or retired), as one line naming it, or
  // nothing. Atlas mutex held (shared).
  std::optional<std::string> Check() const;

 private:
  friend class AtlasStorage;  // restores the links of a map file (no lock: not shared yet)
  static void Restore(KeyFrame* keyframe, KeyFrame* previous, KeyFrame* next);

  const Map* map_;
};

}  // namespace pkslam
