// The tracker's local map (ORB-SLAM3's UpdateLocalKeyFrames, UpdateLocalPoints and
// SearchLocalPoints): the keyframes that see the current frame's matched points, grown by one
// covisible neighbour, one child and the parent of each while under a cap, and those keyframes'
// points, searched by projection into the frame.
//
// Owned by the Tracker and used on its thread only; every call runs under the Atlas lock
// (shared) that Tracker::Track holds. It keeps non-owning keyframe pointers between frames,
// so the tracker clears it whenever the map is reset or replaced.
#pragma once

#include <vector>

#include "core/sensor/camera_rig.h"
#include "map_model/frame.h"
#include "map_model/map_ids.h"

namespace pkslam {

class LocalMap {
 public:
  explicit LocalMap(int max_keyframes) : max_keyframes_(max_keyframes) {}

  // Rebuilds the local keyframes from `frame`'s matches (dropping its matches to retired
  // points), then the local points from the keyframes. Returns the keyframe sharing the most
  // points with the frame, or nullptr when the frame has no match: then the keyframes of the
  // last update stay (as in ORB-SLAM3). With `voters`, the keyframes come from its matches
  // instead: ORB-SLAM3's front end leaves an IMU-predicted frame without matches, and votes with
  // the last frame's (TrackingOptions::InertialSearch::kOrbSlam3).
  KeyFrame* Update(Frame* frame, const Frame* voters = nullptr);

  // Starts from these keyframes and points (a map just initialised).
  void Reset(std::vector<KeyFrame*> keyframes, std::vector<MapPointPtr> points);
  void Clear();

  // Matches local points the frame has not matched yet: those in front of it, inside the image,
  // within their scale-invariance distances and seen less than 60 degrees off their mean
  // normal are counted visible and searched within `radius` pixels (times the level's scale).
  // Counts the frame's own matches visible too. Returns the new matches.
  int Search(Frame* frame, const CameraRig& rig, double radius) const;

  const std::vector<KeyFrame*>& keyframes() const { return keyframes_; }
  const std::vector<MapPointPtr>& points() const { return points_; }

 private:
  KeyFrame* UpdateKeyFrames(const Frame& voters);
  void UpdatePoints();

  int max_keyframes_;
  std::vector<KeyFrame*> keyframes_;
  std::vector<MapPointPtr> points_;
};

}  // namespace pkslam
