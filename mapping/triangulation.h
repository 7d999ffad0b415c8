// Two-view triangulation of keypoint pairs between keyframes with ORB-SLAM's acceptance
// tests (parallax vs stereo, positive depth, reprojection chi2, scale consistency).
#pragma once

#include <Eigen/Core>
#include <optional>

#include "map_model/map_ids.h"

namespace pkslam {

struct TriangulatedPoint {
  Eigen::Vector3d position;
  KeyFrame* other;  // the neighbour keyframe
  int index1;       // keypoint in the new keyframe
  int index2;       // keypoint in the neighbour
};

// Enough baseline between the two keyframes to triangulate (stereo: at least the stereo
// baseline; monocular: baseline / median scene depth >= 0.01). Shared Atlas lock.
bool HasTriangulationBaseline(const KeyFrame& kf1, const KeyFrame& kf2, bool monocular);

// The world point of keypoints i1 (kf1) and i2 (kf2), or nullopt when it fails a test.
// Uses the stereo depth of one view instead when it gives more parallax. Shared lock.
std::optional<Eigen::Vector3d> TriangulatePair(const KeyFrame& kf1, int i1, const KeyFrame& kf2,
                                               int i2, bool monocular);

// Linear (DLT) triangulation of two normalised image rays given 3x4 camera_from_world
// matrices; nullopt if degenerate (point at infinity).
std::optional<Eigen::Vector3d> TriangulateDlt(const Eigen::Vector2d& xn1,
                                              const Eigen::Vector2d& xn2,
                                              const Eigen::Matrix<double, 3, 4>& p1,
                                              const Eigen::Matrix<double, 3, 4>& p2);

}  // namespace pkslam
