// The Tracker's map initialiser: offers each frame of an uninitialised tracker to the parts of
// tracking/map_initializer.h and, once a map starts, hands back its keyframes. Stereo and
// RGB-D: one frame with enough depth readings. Monocular: a pair of frames that reconstructs,
// refined together and scaled to a unit median depth, or refused (then the caller resets the
// map, as ORB-SLAM3 does). The local map is seeded with the new keyframes and their points.
//
// Tracking thread. Takes the Atlas's locks itself; owns the monocular pair's first frame.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "map_model/frame.h"
#include "map_model/map_ids.h"
#include "tracking/local_map.h"
#include "tracking/map_initializer.h"
#include "tracking/tracking_options.h"

namespace pkslam {

class Atlas;
class Vocabulary;

struct StartedMap {
  // The new keyframes, oldest first; empty while no map started.
  std::vector<KeyFramePtr> keyframes;
  // A stereo or RGB-D start's points; a two-view start counts what its second keyframe tracks
  // once local mapping had it (TrackedPoints).
  std::optional<int> depth_points;
  // A two-view start: its first frame, which becomes the tracker's last frame.
  std::optional<Frame> first_of_pair;
  // A two-view map was built and refused (too few points or no depth): the caller resets it.
  bool refused = false;

  bool started() const { return !keyframes.empty(); }
  const KeyFramePtr& newest() const { return keyframes.back(); }
  int TrackedPoints() const;
};

class MapStarter {
 public:
  MapStarter(Atlas* atlas, const Vocabulary* vocabulary, bool monocular,
             const TrackingOptions& options)
      : atlas_(atlas), vocabulary_(vocabulary), monocular_(monocular), options_(options) {}

  // Offers `current` (built, not tracked); on a start it becomes the newest keyframe's frame
  // (posed, its keypoints bound to the new points) and `local_map` holds the new map.
  StartedMap Offer(Frame* current, const AttachKeyFrame& attach, LocalMap* local_map);

  // Monocular: the first frame of the pair being tried (moves with a new calibration and
  // anchors the IMU samples kept).
  Frame* pair_first() { return two_view_.started() ? &two_view_.first() : nullptr; }
  void Reset() { two_view_.Reset(); }

 private:
  StartedMap StartFromDepth(Frame* current, const AttachKeyFrame& attach, LocalMap* local_map);
  StartedMap StartFromTwoViews(const TwoViewResult& reconstruction, Frame* current,
                               const AttachKeyFrame& attach, LocalMap* local_map);

  Atlas* atlas_;
  const Vocabulary* vocabulary_;
  bool monocular_;
  TrackingOptions options_;
  TwoViewStart two_view_;
};

}  // namespace pkslam
