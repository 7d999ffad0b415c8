// Localisation-only tracking (ORB-SLAM's localisation mode) against a loaded map: no keyframes,
// no points, no map resets. A frame that cannot be tracked is relocalised; where the map has too
// few points in view, stereo and RGB-D frames go on by visual odometry (temporary points from
// the previous frame's depth) while every frame also tries to relocalise, and a relocalisation
// wins. Without it a 10 s map lost the camera for good the moment it looked elsewhere.
//
// The policy is here; the moves it chooses between are the tracker's (frame_tracking.h,
// relocaliser.h, local_map.h), given as LocalisationMoves. Owned by the Tracker, tracking
// thread only; the moves run under the Atlas lock the tracker holds (shared).
#pragma once

#include <functional>

#include "map_model/frame.h"

namespace pkslam {

// Inlier matches of `frame`: to map points only (temporary visual-odometry points have no
// observations), or all.
int InlierMatches(const Frame& frame, bool map_only);

// Temporary points for the keypoints of `last` that have depth and no map point, so the motion
// model can track where the map has none: all closer than `th_depth`, and at least
// `min_points` of them, nearest first (ORB-SLAM's UpdateLastFrame in its localisation mode).
void AddVisualOdometryPoints(double th_depth, int min_points, Frame* last);

// The tracker's moves on its current frame, each true when it tracked the frame.
struct LocalisationMoves {
  std::function<bool()> motion_model;        // from the last frame (needs a velocity)
  std::function<bool()> reference_keyframe;  // BoW matching to the reference keyframe
  std::function<bool()> relocalise;          // a place search in the map
  std::function<bool()> local_map;           // the local map search and pose refinement
};

// What the tracker knows of the frame before it is tracked.
struct LocalisationFrame {
  bool last_tracked = false;              // the last frame was tracked (state OK)
  bool has_velocity = false;              // the motion model can predict
  bool after_relocalisation_gap = false;  // at least 2 frames since the last relocalisation
  bool odometry_possible = false;         // stereo / RGB-D: the last frame had depth
};

class LocalisationTracking {
 public:
  // Tracks `current` by the map or by visual odometry; false when the camera is lost.
  bool Track(const LocalisationFrame& frame, const LocalisationMoves& moves, Frame* current);
  // The last frame was tracked by visual odometry, not by the map's points.
  bool visual_odometry() const { return visual_odometry_; }
  // Localisation (re)starts, or the mode was switched: the next frame starts from the map.
  void Restart() { visual_odometry_ = false; }

 private:
  bool visual_odometry_ = false;
};

}  // namespace pkslam
