// The map points a new stereo or RGB-D keyframe brings (ORB-SLAM3's CreateNewKeyFrame, depth
// branch): its closest keypoints with a depth reading that have no map point yet become points,
// all closer than the rig's th_depth and at least the nearest `min_close` of them.
//
// Also tracking's whole keyframe creation (ORB-SLAM3's CreateNewKeyFrame): the keyframe, its
// inertial link and those points.
//
// Tracking thread, with the Atlas's write lock (a parameter: points are added to the map).
#pragma once

#include <optional>

#include "map_model/frame.h"
#include "map_model/map_ids.h"
#include "tracking/map_initializer.h"

namespace pkslam {

class Atlas;
class MapWriteLock;
class Vocabulary;

struct ClosePointRule {
  double th_depth = 0.0;  // the rig's close/far depth threshold (m)
  int min_close = 100;    // at least this many of the nearest keypoints (TrackingOptions)
};

// Creates the points for `frame`'s keypoints as above, observed by `keyframe` (made from
// `frame`) and added to the keyframe's map, and puts them into the frame's slots. A slot whose
// point has observations keeps it; a temporary one (visual odometry) is replaced. Returns the
// points created.
int AddClosePoints(const MapWriteLock& lock, Atlas* atlas, KeyFrame* keyframe,
                   const ClosePointRule& rule, Frame* frame);

// `frame` (its BoW computed here) becomes a keyframe of the Atlas's current map, joins the
// inertial chain after `previous` through `attach` (which may correct the frame's pose: the
// keyframe takes the corrected one), and with `close_points` (stereo and RGB-D) brings its
// close points. Returns the keyframe.
KeyFramePtr CreateKeyFrame(const MapWriteLock& lock, Atlas* atlas, const Vocabulary& vocabulary,
                           const AttachKeyFrame& attach, KeyFrame* previous,
                           const std::optional<ClosePointRule>& close_points, Frame* frame);

}  // namespace pkslam
