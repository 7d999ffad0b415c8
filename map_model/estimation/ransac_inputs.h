// Map -> values for the RANSAC estimators of estimators/ransac: PnP correspondences of a frame's
// matches (relocalisation) and Sim3 pairs of two keyframes' matches (loop and merge detection).
// Requires the Atlas mutex (shared) while reading the map objects.
#pragma once

#include <vector>

#include "core/geometry/pinhole_intrinsics.h"
#include "estimators/ransac/pnp.h"
#include "estimators/ransac/sim3_solver.h"
#include "map_model/map_ids.h"

namespace pkslam {

// Pairs of the frame's keypoints with the map points matched to them (matches[i] for keypoint
// i, null where none; bad points are skipped). Requires the Atlas mutex (shared).
std::vector<PnpCorrespondence> MakePnpCorrespondences(const Frame& frame,
                                                      const std::vector<MapPointPtr>& matches);

// Pairs from ORB-SLAM's loop matching output: matches12[i1] = map point of kf2 matched to
// keypoint i1 of kf1 (or null). A pair is kept when kf1 has a good point at i1, the kf2 point
// is good and observed by kf2. Requires the Atlas mutex (shared).
std::vector<Sim3Match> MakeSim3Matches(const KeyFrame& kf1, const KeyFrame& kf2,
                                       const std::vector<MapPointPtr>& matches12);
PinholeIntrinsics IntrinsicsOf(const KeyFrame& kf);

}  // namespace pkslam
