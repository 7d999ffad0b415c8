#include "map_model/estimation/ransac_inputs.h"

#include <gtest/gtest.h>

#include <mutex>

#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

double CentreError(const SE3d& a, const SE3d& b) {
  return (a.Inverse().translation() - b.Inverse().translation()).norm();
}

TEST(RansacInputsTest, PnpCorrespondencesFromAFrameAndItsMatches) {
  Atlas atlas;
  const auto rig = testing::MakeStereoRig();
  const auto scene = testing::MakeScene(500, 8);
  const auto poses = testing::MakeForwardPath(3, 0.3, 1);
  const auto map = testing::MakeMap(&atlas, scene, rig, poses, {});
  std::vector<int> scene_of;
  const Frame f = testing::MakeFrame(scene, rig, poses[1], 99, 0, {}, &scene_of);
  auto lock = MapReader(atlas).Lock();
  std::vector<MapPointPtr> matches(static_cast<std::size_t>(f.size()));
  int expected = 0;
  for (std::size_t i = 0; i < scene_of.size(); ++i) {
    matches[i] = map.point_of_scene_index[static_cast<std::size_t>(scene_of[i])];
    if (matches[i]) ++expected;
  }
  const auto c = MakePnpCorrespondences(f, matches);
  ASSERT_EQ(static_cast<int>(c.size()), expected);
  for (const auto& x : c) {
    EXPECT_EQ(x.point_world, matches[static_cast<std::size_t>(x.index)]->position());
  }
  PnpRansac ransac(c, {rig->fx, rig->fy, rig->cx, rig->cy}, PnpRansacOptions{});
  const auto r = ransac.Iterate(300);
  ASSERT_TRUE(r.found);
  EXPECT_EQ(r.num_inliers, expected);
  EXPECT_LT(CentreError(r.camera_from_world, poses[1]), 1e-6);
  EXPECT_THROW(MakePnpCorrespondences(f, {}), Error);
}

TEST(RansacInputsTest, Sim3MatchesFromKeyFramesCarryCameraCoordinatesAndKeypoints) {
  Atlas atlas;
  const auto rig = testing::MakeStereoRig();
  const auto scene = testing::MakeScene(800, 5);
  const auto poses = testing::MakeForwardPath(2, 0.4, 2);
  const auto map = testing::MakeMap(&atlas, scene, rig, poses, {});
  auto lock = MapReader(atlas).Lock();
  const KeyFrame& kf1 = *map.keyframes[0];
  const KeyFrame& kf2 = *map.keyframes[1];
  // The synthetic map shares points between keyframes: pair each kf1 point with itself.
  std::vector<MapPointPtr> matches12(static_cast<std::size_t>(kf1.size()));
  int expected = 0;
  for (int i = 0; i < kf1.size(); ++i) {
    const auto& mp = kf1.map_point(i);
    if (mp && mp->IsInKeyFrame(&kf2)) {
      matches12[static_cast<std::size_t>(i)] = mp;
      ++expected;
    }
  }
  const auto matches = MakeSim3Matches(kf1, kf2, matches12);
  ASSERT_EQ(static_cast<int>(matches.size()), expected);
  for (const auto& m : matches) {
    const auto& mp = kf1.map_point(m.index1);
    EXPECT_EQ(mp->IndexInKeyFrame(&kf2), m.index2);
    EXPECT_LT((m.point1 - kf1.camera_from_world() * mp->position()).norm(), 1e-12);
    EXPECT_LT((m.point2 - kf2.camera_from_world() * mp->position()).norm(), 1e-12);
    EXPECT_LT((IntrinsicsOf(kf1).Project(m.point1) - m.uv1).norm(), 1e-3);
    EXPECT_LT((IntrinsicsOf(kf2).Project(m.point2) - m.uv2).norm(), 1e-3);
  }
  Sim3SolverOptions options;
  options.fix_scale = true;
  Sim3Solver solver(matches, IntrinsicsOf(kf1), IntrinsicsOf(kf2), options);
  const auto r = solver.Iterate(300);
  ASSERT_TRUE(r.found);
  EXPECT_EQ(r.num_inliers, expected);
  const SE3d truth = kf1.camera_from_world() * kf2.world_from_camera();
  EXPECT_LT((r.camera1_from_camera2.translation() - truth.translation()).norm(), 1e-6);
  EXPECT_THROW(MakeSim3Matches(kf1, kf2, {}), Error);
}

}  // namespace
}  // namespace pkslam
