#include "rgbd/ransac.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "core/util/error.h"

namespace pkslam::rgbd {
namespace {

TEST(RansacIterationCount, MatchesTheFormula) {
  // log(0.01) / log(1 - 0.5^3) = 34.49 -> 35.
  EXPECT_EQ(RansacIterationCount(0.99, 0.5, 3, 1000), 35);
  // log(0.01) / log(1 - 0.8^3) = 6.42 -> 7.
  EXPECT_EQ(RansacIterationCount(0.99, 0.8, 3, 1000), 7);
  EXPECT_EQ(RansacIterationCount(0.999, 0.3, 3, 1000),
            static_cast<int>(std::ceil(std::log(0.001) / std::log(1 - 0.027))));
  EXPECT_EQ(RansacIterationCount(0.99, 1.0, 3, 1000), 1);
  EXPECT_EQ(RansacIterationCount(0.99, 0.0, 3, 1000), 1000);
  EXPECT_EQ(RansacIterationCount(0.99, 0.05, 3, 1000), 1000);  // 36839 capped
}

struct Problem {
  std::vector<Eigen::Vector3d> source, target;
  std::set<int> outliers;
};

Problem MakeProblem(const SE3d& truth, int n, double outlier_ratio, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  std::normal_distribution<double> g(0.0, noise);
  Problem p;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d s(u(rng), u(rng), 2.5 + u(rng));
    Eigen::Vector3d t = truth * s + Eigen::Vector3d(g(rng), g(rng), g(rng));
    if (i < static_cast<int>(outlier_ratio * n)) {
      t = Eigen::Vector3d(u(rng), u(rng), 2.5 + u(rng));  // a wrong match
      p.outliers.insert(i);
    }
    p.source.push_back(s);
    p.target.push_back(t);
  }
  return p;
}

TEST(Ransac, RecoversTheTransformDespiteOutliers) {
  const SE3d truth(SO3d::Exp(Eigen::Vector3d(0.05, -0.1, 0.08)), Eigen::Vector3d(0.1, -0.05, 0.2));
  const Problem p = MakeProblem(truth, 300, 0.4, 0.004, 7);
  RansacOptions options;
  options.inlier_threshold_m = 0.02;
  const RansacResult r = EstimateRigidRansac(p.source, p.target, options);
  ASSERT_TRUE(r.success);
  const SE3d error = truth.Inverse() * r.target_from_source;
  EXPECT_LT(error.translation().norm(), 0.005);
  EXPECT_LT(error.so3().Angle(), 0.2 * M_PI / 180);
  int outliers_in = 0;
  for (const int i : r.inliers) outliers_in += p.outliers.count(i) > 0;
  EXPECT_EQ(outliers_in, 0);
  EXPECT_GT(static_cast<int>(r.inliers.size()), 170);  // of 180 true inliers
  // Adaptive count: 60% inliers needs ~19 samples, far below the cap.
  EXPECT_LT(r.iterations, 100);
}

TEST(Ransac, FailsWhenTooFewInliers) {
  const Problem p = MakeProblem(SE3d(), 100, 0.95, 0.002, 8);
  RansacOptions options;
  options.min_inliers = 20;
  const RansacResult r = EstimateRigidRansac(p.source, p.target, options);
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.iterations, options.max_iterations);
}

TEST(Ransac, IsDeterministicForASeed) {
  const Problem p = MakeProblem(SE3d(SO3d(), Eigen::Vector3d(0.1, 0, 0)), 100, 0.3, 0.003, 9);
  const RansacOptions options;
  const RansacResult a = EstimateRigidRansac(p.source, p.target, options);
  const RansacResult b = EstimateRigidRansac(p.source, p.target, options);
  EXPECT_EQ(a.inliers, b.inliers);
  EXPECT_EQ(a.target_from_source.Matrix(), b.target_from_source.Matrix());
}

TEST(Ransac, BadOptionsThrow) {
  RansacOptions options;
  options.confidence = 1.0;
  EXPECT_THROW(options.Check(), OptionError);
}

}  // namespace
}  // namespace pkslam::rgbd
