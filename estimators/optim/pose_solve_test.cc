#include "estimators/optim/pose_solve.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/util/error.h"
#include "estimators/ransac/synthetic_views.h"

namespace pkslam {
namespace {

using testing::MakeScenePoints;
using testing::ProjectView;
using testing::ViewRig;

struct PoseCase {
  SE3d truth;
  std::vector<PoseCorrespondence> correspondences;
  std::vector<bool> is_outlier;
  PinholeIntrinsics camera;
};

// A monocular view of a synthetic scene (0.5 px noise) with `outlier_every`-th observation
// moved by 40 px.
PoseCase MakeCase(int outlier_every, std::uint64_t seed) {
  const ViewRig rig;
  const auto scene = MakeScenePoints(500, seed);
  PoseCase c;
  c.camera = rig.intrinsics;
  c.truth = SE3d(SO3d::Exp(Eigen::Vector3d(0.03, -0.05, 0.01)), Eigen::Vector3d(0.2, -0.1, 0.3));
  const auto view = ProjectView(scene, rig, c.truth, 0, 0.5, seed);
  for (std::size_t i = 0; i < view.size(); ++i) {
    PoseCorrespondence& p = c.correspondences.emplace_back();
    p.keypoint = static_cast<int>(i);
    p.p_world = scene.points_world[static_cast<std::size_t>(view[i].point)];
    const bool outlier = outlier_every > 0 && i % static_cast<std::size_t>(outlier_every) == 0;
    const Eigen::Vector2d uv =
        view[i].uv + (outlier ? Eigen::Vector2d(40, -40) : Eigen::Vector2d::Zero());
    p.obs = Eigen::Vector3d(uv.x(), uv.y(), -1.0);
    p.inv_sigma2 = rig.pyramid.inv_sigma2[static_cast<std::size_t>(view[i].octave)];
    c.is_outlier.push_back(outlier);
  }
  return c;
}

double SolvedCentreError(const SE3d& a, const SE3d& b) {
  return (a.Inverse().translation() - b.Inverse().translation()).norm();
}

TEST(SolvePoseTest, RecoversThePoseAndFlagsTheMovedObservations) {
  PoseCase c = MakeCase(10, 3);
  ASSERT_GT(c.correspondences.size(), 200u);
  // Start 5 cm and ~1.7 degrees off.
  const SE3d start =
      SE3d(SO3d::Exp(Eigen::Vector3d(0.0, 0.03, 0.0)), Eigen::Vector3d(0.05, 0.0, 0.0)) * c.truth;
  const SE3d got = SolvePose(c.camera, start, &c.correspondences, PoseOptimizerOptions{});
  EXPECT_LT(SolvedCentreError(got, c.truth), 0.01);
  EXPECT_LT((got.so3().Inverse() * c.truth.so3()).Log().norm(), 0.2 * M_PI / 180.0);
  int wrong = 0;
  for (std::size_t i = 0; i < c.correspondences.size(); ++i) {
    const bool flagged = c.correspondences[i].block == nullptr;
    wrong += flagged != c.is_outlier[i] ? 1 : 0;
  }
  EXPECT_LE(wrong, 3) << "of " << c.correspondences.size();
}

TEST(SolvePoseTest, SameInputSameOutputAndChecksItsInput) {
  PoseCase a = MakeCase(7, 5);
  PoseCase b = MakeCase(7, 5);
  const SE3d start = SE3d(SO3d(), Eigen::Vector3d(0.02, 0.01, 0.0)) * a.truth;
  const SE3d ra = SolvePose(a.camera, start, &a.correspondences, PoseOptimizerOptions{});
  const SE3d rb = SolvePose(b.camera, start, &b.correspondences, PoseOptimizerOptions{});
  EXPECT_EQ(ra.Matrix(), rb.Matrix());
  std::vector<PoseCorrespondence> none;
  EXPECT_THROW(SolvePose(a.camera, start, &none, PoseOptimizerOptions{}), Error);
  PoseOptimizerOptions bad;
  bad.rounds = 0;
  EXPECT_THROW(SolvePose(a.camera, start, &a.correspondences, bad), OptionError);
}

}  // namespace
}  // namespace pkslam
