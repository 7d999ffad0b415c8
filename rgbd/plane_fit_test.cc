#include "rgbd/plane_fit.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "core/util/error.h"

namespace pkslam::rgbd {
namespace {

// Points on the plane n.x = d (n unit), spread over ~1 m, with Gaussian noise along n.
PointMoments NoisyPlane(const Eigen::Vector3d& n, double d, int count, double noise, unsigned seed,
                        std::vector<Eigen::Vector3d>* points = nullptr) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  std::normal_distribution<double> g(0.0, noise);
  const Eigen::Vector3d a = n.unitOrthogonal();
  const Eigen::Vector3d b = n.cross(a);
  PointMoments moments;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d p = d * n + u(rng) * a + u(rng) * b + g(rng) * n;
    moments.Add(p);
    if (points != nullptr) points->push_back(p);
  }
  return moments;
}

TEST(PlaneFit, LeastSquaresAndPcaAgreeOnNoisyPlanes) {
  const Eigen::Vector3d normals[] = {Eigen::Vector3d(0, 0, -1),
                                     Eigen::Vector3d(0.3, -0.2, -1).normalized(),
                                     Eigen::Vector3d(0, -1, -0.6).normalized()};
  unsigned seed = 1;
  for (const Eigen::Vector3d& n : normals) {
    const double d = -2.0;  // the plane is 2 m in front of the camera (normal faces it)
    const PointMoments m = NoisyPlane(n, d, 2000, 0.005, seed++);
    const auto ls = m.Fit(PlaneFitMethod::kLeastSquares);
    const auto pca = m.Fit(PlaneFitMethod::kPca);
    ASSERT_TRUE(ls && pca);
    EXPECT_LT(NormalAngleDeg(*ls, *pca), 0.5);
    EXPECT_LT(NormalAngleDeg(*ls, Plane{n, d}), 0.5);
    EXPECT_NEAR(ls->d, d, 0.005);
    EXPECT_NEAR(pca->d, d, 0.005);
    EXPECT_LT(ls->normal.dot(m.Mean()), 0.0);  // faces the camera
    EXPECT_NEAR(m.RmsDistance(*pca), 0.005, 0.001);
  }
}

TEST(PlaneFit, LeastSquaresIsEquationSix) {
  // Exact points on z = 0.2 x - 0.1 y + 3: Eq. 6 gives A = 0.2, B = -0.1, C = 3, so the normal
  // is (A, B, -1) normalised and d = n . centroid.
  PointMoments m;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 4; ++j) {
      const double x = 0.1 * i - 0.2, y = 0.15 * j - 0.2;
      m.Add(Eigen::Vector3d(x, y, 0.2 * x - 0.1 * y + 3));
    }
  }
  const auto plane = m.Fit(PlaneFitMethod::kLeastSquares);
  ASSERT_TRUE(plane);
  const Eigen::Vector3d expected = Eigen::Vector3d(0.2, -0.1, -1).normalized();
  EXPECT_LT((plane->normal - expected).norm(), 1e-12);
  EXPECT_NEAR(plane->d, expected.dot(m.Mean()), 1e-12);
  EXPECT_NEAR(m.RmsDistance(*plane), 0.0, 1e-6);
}

TEST(PlaneFit, DegenerateSegmentsHaveNoPlane) {
  PointMoments two;
  two.Add({0, 0, 1});
  two.Add({1, 0, 1});
  EXPECT_FALSE(two.Fit(PlaneFitMethod::kPca));
  PointMoments line;
  for (int i = 0; i < 10; ++i) line.Add(Eigen::Vector3d(0.1 * i, 0.05 * i, 2));
  EXPECT_FALSE(line.Fit(PlaneFitMethod::kLeastSquares));
  EXPECT_FALSE(line.Fit(PlaneFitMethod::kPca));
  // A plane containing the viewing direction (x = 0.5): z = f(x, y) is singular, PCA fits it.
  PointMoments edge_on;
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 10; ++j) edge_on.Add(Eigen::Vector3d(0.5, 0.1 * i, 1 + 0.1 * j));
  }
  EXPECT_FALSE(edge_on.Fit(PlaneFitMethod::kLeastSquares));
  const auto pca = edge_on.Fit(PlaneFitMethod::kPca);
  ASSERT_TRUE(pca);
  EXPECT_NEAR(std::abs(pca->normal.x()), 1.0, 1e-9);
}

TEST(PlaneFit, ProjectionLandsOnThePlaneAlongTheNormal) {
  const Plane plane{Eigen::Vector3d(1, 2, -2).normalized(), -1.5};
  const Eigen::Vector3d p(0.3, -0.7, 2.2);
  const Eigen::Vector3d q = plane.Project(p);
  EXPECT_NEAR(plane.SignedDistance(q), 0.0, 1e-12);
  EXPECT_LT((p - q).cross(plane.normal).norm(), 1e-12);  // moved along the normal
  EXPECT_NEAR((p - q).norm(), std::abs(plane.SignedDistance(p)), 1e-12);
  // Eq. 7 with a non-unit normal gives the same distance.
  const Eigen::Vector3d abc = 3.0 * plane.normal;
  EXPECT_NEAR((abc.dot(p) - 3.0 * plane.d) / abc.norm(), plane.SignedDistance(p), 1e-12);
}

TEST(PointMoments, SumsDescribeTheUnion) {
  std::vector<Eigen::Vector3d> a_points, b_points;
  PointMoments a = NoisyPlane(Eigen::Vector3d(0, 0, -1), -2, 100, 0.01, 5, &a_points);
  const PointMoments b = NoisyPlane(Eigen::Vector3d(0, 0, -1), -2.5, 50, 0.01, 6, &b_points);
  PointMoments direct;
  for (const auto& p : a_points) direct.Add(p);
  for (const auto& p : b_points) direct.Add(p);
  a.Add(b);
  EXPECT_EQ(a.count(), 150u);
  EXPECT_LT((a.Covariance() - direct.Covariance()).norm(), 1e-12);
  const auto plane = a.Fit(PlaneFitMethod::kPca);
  ASSERT_TRUE(plane);
  EXPECT_GT(a.RmsDistance(*plane), 0.2);  // two parallel planes 0.5 m apart are not one plane
}

TEST(PlaneFit, ParsesMethodNames) {
  EXPECT_EQ(ParsePlaneFitMethod("ls"), PlaneFitMethod::kLeastSquares);
  EXPECT_EQ(ParsePlaneFitMethod("pca"), PlaneFitMethod::kPca);
  EXPECT_THROW(ParsePlaneFitMethod("svd"), OptionError);
}

}  // namespace
}  // namespace pkslam::rgbd
