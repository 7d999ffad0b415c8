// Planes fitted to segment points (seed 001, section 3-1-2 and 3-2).
//   Least squares (the paper's Eq. 6): z = A x + B y + C from the normal equations, i.e. the
//   plane A x + B y - z + C = 0 with normal (A, B, -1). Solved on centred sums (the same
//   solution; the raw sums of Eq. 6 lose digits when the points are far from the origin).
//   It cannot represent planes containing the viewing (z) direction -- those are seen edge-on
//   and their segments are (nearly) lines in the image, where the system is singular.
//   PCA: the normal is the eigenvector of the smallest eigenvalue of the points' covariance
//   (total least squares; any orientation).
// Both return a unit normal oriented towards the camera (n . centroid < 0) and d = n . centroid
// (Eq. 10), so the plane is n . x = d; point-plane distance n . x - d (Eq. 7); projection onto
// the plane P' = P + t n with t = d - n . P (Eqs. 8-9 with a unit normal).
#pragma once

#include <Eigen/Core>
#include <optional>

namespace pkslam::rgbd {

enum class PlaneFitMethod { kLeastSquares, kPca };
// "ls" | "pca"; throws OptionError otherwise.
PlaneFitMethod ParsePlaneFitMethod(const std::string& name);
const char* PlaneFitMethodName(PlaneFitMethod method);

struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit
  double d = 0;                                       // normal . x = d on the plane

  double SignedDistance(const Eigen::Vector3d& p) const { return normal.dot(p) - d; }
  Eigen::Vector3d Project(const Eigen::Vector3d& p) const { return p - SignedDistance(p) * normal; }
};

// First and second moments of a point set; sums of two sets describe their union, so merged
// segments are refitted without revisiting their points.
class PointMoments {
 public:
  void Add(const Eigen::Vector3d& p);
  void Add(const PointMoments& other);
  std::size_t count() const { return count_; }
  Eigen::Vector3d Mean() const;
  // Covariance about the mean (divided by the count).
  Eigen::Matrix3d Covariance() const;

  // nullopt with fewer than 3 points or a singular system (collinear points; for least
  // squares also planes containing the z axis).
  std::optional<Plane> Fit(PlaneFitMethod method) const;
  // Root mean square of the point-plane distances of these points to `plane`.
  double RmsDistance(const Plane& plane) const;

 private:
  std::size_t count_ = 0;
  Eigen::Vector3d sum_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum_outer_ = Eigen::Matrix3d::Zero();
};

// Angle between two planes' normals in degrees, in [0, 90] (orientation ignored).
double NormalAngleDeg(const Plane& a, const Plane& b);

}  // namespace pkslam::rgbd
