// Motion from two-view models and the cheirality / parallax test of a motion hypothesis:
// essential-matrix decomposition (four hypotheses), Faugeras' homography decomposition
// (eight hypotheses), linear (DLT) triangulation, and ORB-SLAM's CheckRT rule for counting
// well-triangulated correspondences. Pure functions; thread-safe.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "estimators/two_view/two_view_models.h"

namespace pkslam::two_view {

// Ideal pinhole intrinsics of one view (undistorted keypoints).
struct Pinhole {
  double fx = 1, fy = 1, cx = 0, cy = 0;
  Eigen::Matrix3d K() const;
  Eigen::Vector2d Project(const Eigen::Vector3d& p) const {
    return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
  }
  // Point on the z = 1 plane for a pixel.
  Eigen::Vector2d Normalize(const Eigen::Vector2d& uv) const {
    return {(uv.x() - cx) / fx, (uv.y() - cy) / fy};
  }
};

// A candidate camera2_from_camera1 motion: p2 = rotation * p1 + translation (|t| = 1).
struct Motion {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
};

// E = U diag(1, 1, 0) V^T -> {U W V^T, U W^T V^T} x {+u3, -u3}: the four motions
// (rotations forced to det +1). Order: (R1, t), (R2, t), (R1, -t), (R2, -t).
std::vector<Motion> DecomposeEssential(const Eigen::Matrix3d& e21);

// Faugeras-Lustman decomposition of a calibrated homography a21 = K2^-1 H21 K1 into the eight
// (R, t, n) solutions of a21 ~ R + t n^T / d (four for d' = +d2, four for d' = -d2).
// Empty when two singular values are (nearly) equal: the motion is then not recoverable from
// the homography (pure rotation, or motion along the plane normal).
struct PlanarMotion {
  Motion motion;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // plane normal in camera 1
};
std::vector<PlanarMotion> DecomposeHomography(const Eigen::Matrix3d& a21);

// Linear (DLT) triangulation from normalised image points x1 (camera 1 = [I|0]) and x2
// (camera 2 = [R|t]). Returns the point in camera 1; non-finite when the rays are parallel
// (point at infinity).
Eigen::Vector3d TriangulateLinear(const Eigen::Vector2d& x1, const Eigen::Vector2d& x2,
                                  const Motion& motion);

// Cosine threshold below which a point counts as triangulated (parallax > ~0.36 degrees);
// points with less parallax still count as "good" when their reprojection is fine, whatever
// the sign of their depth (ORB-SLAM's rule: they carry no depth information either way).
inline constexpr double kTriangulatedCosParallax = 0.99998;

// Outcome of CheckMotion over the model's inlier correspondences.
struct MotionCheck {
  int num_good = 0;                        // correspondences passing all tests
  double parallax_deg = 0;                 // ORB-SLAM's robust parallax of the good points
  std::vector<Eigen::Vector3d> points;     // per correspondence, camera-1 coordinates
  std::vector<std::uint8_t> triangulated;  // good and with parallax (kTriangulatedCosParallax)
};

// ORB-SLAM's CheckRT: for each inlier correspondence triangulate; it is good when the point is
// finite, in front of both cameras (unless its parallax is negligible), and reprojects within
// max_reprojection_error2 (squared pixels) in both images. The reported parallax is the
// (kParallaxRank + 1)-th largest ray angle of the good points (the smallest one if fewer), a
// rank statistic robust to a few far points and to a few spurious large angles.
inline constexpr int kParallaxRank = 50;
MotionCheck CheckMotion(const Motion& motion, const Correspondences& pixels,
                        const Correspondences& normalized, const std::vector<std::uint8_t>& inliers,
                        const Pinhole& camera1, const Pinhole& camera2,
                        double max_reprojection_error2);

}  // namespace pkslam::two_view
