#include "estimators/ransac/sim3_solver.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/util/error.h"
#include "estimators/ransac/sim3_test_data.h"

namespace pkslam {
namespace {

using testing::MakeSim3Problem;
using testing::Sim3Problem;
using testing::Sim3ProblemOptions;

double RotationErrorDeg(const Sim3d& a, const Sim3d& b) {
  return (a.so3().Inverse() * b.so3()).Log().norm() * 180.0 / M_PI;
}

TEST(AlignPointsTest, RecoversAnExactSimilarityAndRejectsDegenerateSets) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  const Sim3d truth(1.7, SO3d::Exp(Eigen::Vector3d(0.3, -0.2, 0.9)), Eigen::Vector3d(1, -2, 0.5));
  std::vector<Eigen::Vector3d> source, target;
  for (int i = 0; i < 10; ++i) {
    source.emplace_back(g(rng), g(rng), 3 + g(rng));
    target.push_back(truth * source.back());
  }
  const auto sim = AlignPoints(source, target, false);
  ASSERT_TRUE(sim.has_value());
  EXPECT_NEAR(sim->scale(), 1.7, 1e-9);
  EXPECT_LT(RotationErrorDeg(*sim, truth), 1e-7);
  EXPECT_LT((sim->translation() - truth.translation()).norm(), 1e-9);

  // Three points are enough.
  const std::vector<Eigen::Vector3d> s3(source.begin(), source.begin() + 3);
  const std::vector<Eigen::Vector3d> t3(target.begin(), target.begin() + 3);
  const auto minimal = AlignPoints(s3, t3, false);
  ASSERT_TRUE(minimal.has_value());
  EXPECT_NEAR(minimal->scale(), 1.7, 1e-9);

  // Fixed scale: a rigid transform of rigid data is exact too.
  const Sim3d rigid(1.0, truth.so3(), truth.translation());
  std::vector<Eigen::Vector3d> rigid_target(source.size());
  for (std::size_t i = 0; i < source.size(); ++i) rigid_target[i] = rigid * source[i];
  const auto se3 = AlignPoints(source, rigid_target, true);
  ASSERT_TRUE(se3.has_value());
  EXPECT_EQ(se3->scale(), 1.0);
  EXPECT_LT(RotationErrorDeg(*se3, rigid), 1e-7);

  // Collinear sources and too few points have no unique rotation.
  const std::vector<Eigen::Vector3d> line = {{0, 0, 1}, {1, 1, 2}, {2, 2, 3}};
  EXPECT_FALSE(AlignPoints(line, t3, false).has_value());
  EXPECT_FALSE(AlignPoints({s3[0], s3[1]}, {t3[0], t3[1]}, false).has_value());
}

TEST(Sim3SolverTest, MonocularLoopWithOutliersRecoversScaleAndPose) {
  Sim3ProblemOptions po;
  po.scale = 1.35;
  po.outlier_fraction = 0.4;
  const Sim3Problem p = MakeSim3Problem(po);
  ASSERT_GT(p.matches.size(), 150u);
  Sim3SolverOptions options;
  options.seed = 7;
  Sim3Solver solver(p.matches, p.camera, p.camera, options);
  const auto result = solver.Iterate(300);
  ASSERT_TRUE(result.found);
  EXPECT_NEAR(result.camera1_from_camera2.scale(), 1.35, 0.02);
  EXPECT_LT(RotationErrorDeg(result.camera1_from_camera2, p.camera1_from_camera2), 0.5);
  EXPECT_LT(
      (result.camera1_from_camera2.translation() - p.camera1_from_camera2.translation()).norm(),
      0.05 * p.camera1_from_camera2.translation().norm());
  int true_positive = 0, false_positive = 0, true_inliers = 0;
  for (std::size_t i = 0; i < p.matches.size(); ++i) {
    true_inliers += p.is_inlier[i] ? 1 : 0;
    if (result.inliers[i]) (p.is_inlier[i] ? true_positive : false_positive)++;
  }
  EXPECT_EQ(result.num_inliers, true_positive + false_positive);
  EXPECT_LE(false_positive, 2);
  EXPECT_GT(true_positive, 0.9 * true_inliers);
}

TEST(Sim3SolverTest, FixedScaleGivesARigidTransform) {
  Sim3ProblemOptions po;
  po.scale = 1.0;
  po.outlier_fraction = 0.3;
  const Sim3Problem p = MakeSim3Problem(po);
  Sim3SolverOptions options;
  options.fix_scale = true;
  Sim3Solver solver(p.matches, p.camera, p.camera, options);
  const auto result = solver.Iterate(300);
  ASSERT_TRUE(result.found);
  EXPECT_EQ(result.camera1_from_camera2.scale(), 1.0);
  EXPECT_LT(RotationErrorDeg(result.camera1_from_camera2, p.camera1_from_camera2), 0.5);
}

TEST(Sim3SolverTest, IterateInSmallStepsRespectsTheBudgetAndGivesUpOnNoise) {
  // Only outliers: no hypothesis can collect 20 inliers; the solver stops after its budget.
  Sim3ProblemOptions po;
  po.outlier_fraction = 1.0;
  const Sim3Problem p = MakeSim3Problem(po);
  Sim3SolverOptions options;
  options.max_iterations = 40;
  Sim3Solver solver(p.matches, p.camera, p.camera, options);
  EXPECT_EQ(solver.iteration_budget(), 40);
  int calls = 0;
  Sim3RansacResult r;
  do {
    const int before = solver.iterations_done();
    r = solver.Iterate(5);
    EXPECT_LE(solver.iterations_done() - before, 5);
    ++calls;
  } while (!r.found && !r.exhausted && calls < 100);
  EXPECT_FALSE(r.found);
  EXPECT_TRUE(r.exhausted);
  EXPECT_EQ(calls, 8);
  EXPECT_EQ(solver.iterations_done(), 40);
  EXPECT_FALSE(solver.Iterate(5).found);  // nothing left
  EXPECT_EQ(solver.iterations_done(), 40);

  // Fewer matches than min_inliers: exhausted at once.
  std::vector<Sim3Match> few(p.matches.begin(), p.matches.begin() + 10);
  Sim3Solver small(few, p.camera, p.camera, Sim3SolverOptions{});
  EXPECT_TRUE(small.Iterate(5).exhausted);

  // ORB-SLAM's budget: iterations to draw an all-inlier triple with 99% probability when only
  // min_inliers of the matches are inliers; 40 matches -> (1/2)^3 per draw -> 35 iterations.
  Sim3ProblemOptions clean;
  clean.outlier_fraction = 0.0;
  const Sim3Problem q = MakeSim3Problem(clean);
  Sim3Solver easy({q.matches.begin(), q.matches.begin() + 40}, q.camera, q.camera,
                  Sim3SolverOptions{});
  EXPECT_EQ(easy.iteration_budget(), 35);
  // Minimal samples are noisy (1% depth noise): a few draws may be needed, within the budget.
  Sim3RansacResult found;
  while (!found.found && !found.exhausted) found = easy.Iterate(5);
  EXPECT_TRUE(found.found);
  EXPECT_GE(found.num_inliers, 30);
}

TEST(Sim3SolverTest, SameSeedSameResult) {
  Sim3ProblemOptions po;
  po.outlier_fraction = 0.5;
  const Sim3Problem p = MakeSim3Problem(po);
  Sim3SolverOptions options;
  options.seed = 42;
  Sim3Solver a(p.matches, p.camera, p.camera, options);
  Sim3Solver b(p.matches, p.camera, p.camera, options);
  const auto ra = a.Iterate(300);
  const auto rb = b.Iterate(300);
  ASSERT_TRUE(ra.found);
  EXPECT_EQ(a.iterations_done(), b.iterations_done());
  EXPECT_EQ(ra.inliers, rb.inliers);
  EXPECT_EQ(ra.camera1_from_camera2.Matrix(), rb.camera1_from_camera2.Matrix());
}

TEST(Sim3SolverTest, OptionsAreChecked) {
  Sim3SolverOptions o;
  o.probability = 1.0;
  EXPECT_THROW(o.Check(), OptionError);
  o = {};
  o.min_inliers = 2;
  EXPECT_THROW(o.Check(), OptionError);
}

}  // namespace
}  // namespace pkslam
