// The map points a new stereo or RGB-D keyframe brings (ORB-SLAM3's CreateNewKeyFrame, depth
// branch): its closest keypoints with a depth reading that have no map point yet become points,
// all closer than the rig's th_depth and at least the nearest `min_close` of them.
//
// Tracking thread, with the Atlas's write lock (a parameter: points are added to the map).
#pragma once

#include "map_model/frame.h"
#include "map_model/map_ids.h"

namespace pkslam {

class Atlas;
class MapWriteLock;

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

}  // namespace pkslam
