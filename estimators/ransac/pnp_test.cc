#include "estimators/ransac/pnp.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/util/error.h"
#include "estimators/ransac/pnp_test_data.h"

namespace pkslam {
namespace {

using testing::MakePnpProblem;
using testing::PnpProblem;

double RotationErrorDeg(const SE3d& a, const SE3d& b) {
  return (a.so3().Inverse() * b.so3()).Log().norm() * 180.0 / M_PI;
}
double CentreError(const SE3d& a, const SE3d& b) {
  return (a.Inverse().translation() - b.Inverse().translation()).norm();
}

TEST(PnpRansacTest, RecoversThePoseAndTheInliersUnderHalfOutliers) {
  const PnpProblem p = MakePnpProblem(0.45, 1.0, 3);
  ASSERT_GT(p.correspondences.size(), 150u);
  PnpRansac ransac(p.correspondences, p.camera, PnpRansacOptions{});
  PnpResult r;
  while (!r.found && !r.exhausted) r = ransac.Iterate(5);
  ASSERT_TRUE(r.found);
  EXPECT_LT(RotationErrorDeg(r.camera_from_world, p.camera_from_world), 0.2);
  EXPECT_LT(CentreError(r.camera_from_world, p.camera_from_world), 0.02);
  int tp = 0, fp = 0, truth = 0;
  for (std::size_t i = 0; i < p.is_inlier.size(); ++i) {
    truth += p.is_inlier[i] ? 1 : 0;
    if (r.inliers[i]) (p.is_inlier[i] ? tp : fp)++;
  }
  EXPECT_EQ(r.num_inliers, tp + fp);
  EXPECT_GT(tp, 0.93 * truth);
  EXPECT_LE(fp, 3);
}

TEST(PnpRansacTest, OpenGvRansacAgreesAndIsReproducibleWithASeed) {
  const PnpProblem p = MakePnpProblem(0.3, 1.0, 4);
  PnpRansacOptions options;
  options.seed = 9;
  const PnpResult a = SolvePnpOpenGvRansac(p.correspondences, p.camera, 2.5, options);
  const PnpResult b = SolvePnpOpenGvRansac(p.correspondences, p.camera, 2.5, options);
  ASSERT_TRUE(a.found);
  EXPECT_EQ(a.camera_from_world.Matrix(), b.camera_from_world.Matrix());
  EXPECT_EQ(a.inliers, b.inliers);
  EXPECT_LT(RotationErrorDeg(a.camera_from_world, p.camera_from_world), 0.2);
  EXPECT_LT(CentreError(a.camera_from_world, p.camera_from_world), 0.02);
  EXPECT_NEAR(AngularThreshold(435.0, 435.0), 1.0 - std::cos(M_PI / 4), 1e-12);
}

TEST(PnpRansacTest, SameSeedSameResultAndBudgetIsRespected) {
  const PnpProblem p = MakePnpProblem(0.4, 1.0, 5);
  PnpRansacOptions options;
  options.seed = 11;
  PnpRansac a(p.correspondences, p.camera, options);
  PnpRansac b(p.correspondences, p.camera, options);
  const PnpResult ra = a.Iterate(300);
  const PnpResult rb = b.Iterate(300);
  ASSERT_TRUE(ra.found);
  EXPECT_EQ(a.iterations_done(), b.iterations_done());
  EXPECT_EQ(ra.camera_from_world.Matrix(), rb.camera_from_world.Matrix());
  EXPECT_EQ(ra.inliers, rb.inliers);
  // Budget: min(300, iterations for a 4-sample at the acceptance ratio ~0.5) ~ 72.
  EXPECT_GE(a.iteration_budget(), 68);
  EXPECT_LE(a.iteration_budget(), 72);
  EXPECT_EQ(a.required_inliers(),
            static_cast<int>(std::ceil(0.5 * static_cast<double>(p.correspondences.size()))));

  // Only wrong matches: never found, exhausted after the budget in steps of 5.
  const PnpProblem bad = MakePnpProblem(1.0, 1.0, 6);
  PnpRansac hopeless(bad.correspondences, bad.camera, options);
  PnpResult r;
  int calls = 0;
  while (!r.found && !r.exhausted && calls < 1000) {
    r = hopeless.Iterate(5);
    ++calls;
  }
  EXPECT_FALSE(r.found);
  EXPECT_TRUE(r.exhausted);
  EXPECT_EQ(hopeless.iterations_done(), hopeless.iteration_budget());
  // Too few correspondences: nothing to try.
  PnpRansac tiny({p.correspondences.begin(), p.correspondences.begin() + 5}, p.camera, options);
  EXPECT_TRUE(tiny.Iterate(5).exhausted);
}

TEST(PnpRansacTest, OptionsAreChecked) {
  PnpRansacOptions o;
  o.min_inliers = 3;
  EXPECT_THROW(o.Check(), OptionError);
}

}  // namespace
}  // namespace pkslam
