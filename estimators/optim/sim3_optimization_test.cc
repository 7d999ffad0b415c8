#include "estimators/optim/sim3_optimization.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/util/error.h"
#include "estimators/ransac/sim3_test_data.h"

namespace pkslam {
namespace {

using testing::MakeSim3Problem;
using testing::Sim3Problem;
using testing::Sim3ProblemOptions;

double Sim3RotationErrorDeg(const Sim3d& a, const Sim3d& b) {
  return (a.so3().Inverse() * b.so3()).Log().norm() * 180.0 / M_PI;
}

// The truth disturbed by ~2 degrees, 10 cm and 6% scale (what a 3-point RANSAC model can be
// off by).
Sim3d Disturb(const Sim3d& truth, bool keep_scale) {
  const Sim3d delta(keep_scale ? 1.0 : 1.06, SO3d::Exp(Eigen::Vector3d(0.02, -0.025, 0.015)),
                    Eigen::Vector3d(0.08, -0.05, 0.04));
  return delta * truth;
}

TEST(OptimizeSim3Test, ConvergesFromADisturbedModelAndFlagsWrongMatches) {
  Sim3ProblemOptions po;
  po.scale = 0.8;
  po.outlier_fraction = 0.25;
  const Sim3Problem p = MakeSim3Problem(po);
  const Sim3d initial = Disturb(p.camera1_from_camera2, false);
  ASSERT_GT(Sim3RotationErrorDeg(initial, p.camera1_from_camera2), 1.5);
  const auto r = OptimizeSim3(p.matches, p.camera, p.camera, initial, {});
  ASSERT_GT(r.num_inliers, 0);
  EXPECT_NEAR(r.camera1_from_camera2.scale(), 0.8, 0.008);
  EXPECT_LT(Sim3RotationErrorDeg(r.camera1_from_camera2, p.camera1_from_camera2), 0.2);
  EXPECT_LT((r.camera1_from_camera2.translation() - p.camera1_from_camera2.translation()).norm(),
            0.02);
  int true_positive = 0, false_positive = 0, true_inliers = 0;
  for (std::size_t i = 0; i < p.matches.size(); ++i) {
    true_inliers += p.is_inlier[i] ? 1 : 0;
    if (r.inliers[i]) (p.is_inlier[i] ? true_positive : false_positive)++;
  }
  EXPECT_EQ(r.num_inliers, true_positive + false_positive);
  EXPECT_LE(false_positive, 2);
  EXPECT_GT(true_positive, 0.95 * true_inliers);
  EXPECT_LT(r.final_cost, r.initial_cost);
}

TEST(OptimizeSim3Test, FixedScaleStaysFixed) {
  Sim3ProblemOptions po;
  po.scale = 1.0;
  const Sim3Problem p = MakeSim3Problem(po);
  Sim3OptimizationOptions options;
  options.fix_scale = true;
  const auto r =
      OptimizeSim3(p.matches, p.camera, p.camera, Disturb(p.camera1_from_camera2, true), options);
  ASSERT_GT(r.num_inliers, 0);
  EXPECT_EQ(r.camera1_from_camera2.scale(), 1.0);
  EXPECT_LT(Sim3RotationErrorDeg(r.camera1_from_camera2, p.camera1_from_camera2), 0.2);
}

TEST(OptimizeSim3Test, FailsWhenTooFewPairsSurviveTheFirstRound) {
  Sim3ProblemOptions po;
  po.outlier_fraction = 1.0;  // nothing is consistent
  const Sim3Problem p = MakeSim3Problem(po);
  const auto r = OptimizeSim3(p.matches, p.camera, p.camera, p.camera1_from_camera2, {});
  EXPECT_EQ(r.num_inliers, 0);
  EXPECT_EQ(std::count(r.inliers.begin(), r.inliers.end(), true), 0);
  EXPECT_EQ(OptimizeSim3({}, p.camera, p.camera, p.camera1_from_camera2, {}).num_inliers, 0);
}

TEST(OptimizeSim3Test, IsDeterministic) {
  const Sim3Problem p = MakeSim3Problem({});
  const Sim3d initial = Disturb(p.camera1_from_camera2, false);
  const auto a = OptimizeSim3(p.matches, p.camera, p.camera, initial, {});
  const auto b = OptimizeSim3(p.matches, p.camera, p.camera, initial, {});
  EXPECT_EQ(a.camera1_from_camera2.Matrix(), b.camera1_from_camera2.Matrix());
  EXPECT_EQ(a.inliers, b.inliers);
  Sim3OptimizationOptions bad;
  bad.chi2 = 0;
  EXPECT_THROW(OptimizeSim3(p.matches, p.camera, p.camera, initial, bad), OptionError);
}

}  // namespace
}  // namespace pkslam
