// ORB-SLAM's quadtree ("octree") keypoint distribution: split the image area into nodes until
// there are as many nodes as wanted keypoints, keeping the strongest keypoint of each node.
#pragma once

#include <opencv2/core.hpp>
#include <span>
#include <vector>

namespace pkslam {

// Returns the indices (ascending) of at most `target` keypoints of `candidates` chosen by
// quadtree splitting of the `area` (candidate pt in [0, area.width) x [0, area.height)):
// initial nodes side by side along x (about square), then rounds in which every node with more
// than one keypoint is split into four; once a full round could overshoot `target`, only the
// most populated nodes are split, largest first, until `target` nodes exist. Each surviving
// node keeps its highest-response keypoint. Unlike ORB-SLAM, which can return up to 3 extra
// keypoints, the result is trimmed to `target` by response. Ties break by candidate index,
// so the result is deterministic.
std::vector<int> DistributeQuadtree(std::span<const cv::KeyPoint> candidates, cv::Size area,
                                    int target);

}  // namespace pkslam
