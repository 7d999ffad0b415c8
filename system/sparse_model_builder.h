// Builds the run's sparse model (io/sparse_model.h) from a SlamSystem: the largest map's live
// keyframes (final poses, undistorted keypoints, the map point of each keypoint) and its map
// points with their observations. Reads under the Atlas shared lock (call it after
// Shutdown, or while the threads run: the snapshot is consistent either way).
#pragma once

#include "io/sparse_model.h"
#include "system/slam_system.h"

namespace pkslam {

SparseModel BuildSparseModel(const SlamSystem& system);

}  // namespace pkslam
