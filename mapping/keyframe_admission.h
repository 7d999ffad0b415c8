// A keyframe from tracking enters the map (ORB-SLAM3's ProcessNewKeyFrame): it becomes an
// observer of the points tracking matched in it, its covisibility links are made, and it is
// indexed for place recognition. Mapping thread, with the Atlas's write lock (a parameter).
#pragma once

#include <vector>

#include "map_model/map_ids.h"

namespace pkslam {

class Atlas;
class MapWriteLock;

// Admits `keyframe` (nothing when it was retired or its map dropped meanwhile). Returns the
// points tracking created for it (stereo/RGB-D close points, already observed by it), which
// local mapping then watches (RecentPoints).
std::vector<MapPointPtr> AdmitKeyFrame(const MapWriteLock& lock, Atlas* atlas, KeyFrame* keyframe);

}  // namespace pkslam
