#include <gtest/gtest.h>

#include <cmath>
#include <mutex>

#include "core/util/error.h"
#include "map_model/estimation/essential_graph_collect.h"
#include "map_model/map_editor.h"
#include "map_model/testing/loop_scenario.h"

namespace pkslam {
namespace {

using testing::BuildLoopScenario;
using testing::KeyFramePositionRmse;
using testing::LoopScenario;
using testing::LoopScenarioOptions;
using testing::MakeCylinderScene;
using testing::PointRmse;
using EdgeKind = EssentialGraphProblem::EdgeKind;

struct Outcome {
  double kf_rmse_before = 0, kf_rmse_after = 0;
  double point_rmse_before = 0, point_rmse_after = 0;
  EssentialGraphProblem problem;
  EssentialGraphResult result;
};

Outcome CloseLoop(LoopScenario* s, const testing::SyntheticScene& scene, PoseGraphDof dof) {
  Outcome out;
  EssentialGraphOptions options;
  options.dof = dof;
  out.kf_rmse_before = KeyFramePositionRmse(*s);
  out.point_rmse_before = PointRmse(*s, scene);
  {
    auto lock = MapReader(s->atlas).Lock();
    out.problem = CollectEssentialGraph(s->map, s->correction, options);
  }
  out.result = SolveEssentialGraph(out.problem, options);
  {
    auto lock = MapEditor(&s->atlas).Write(MapEdit::kFixture);
    ApplyEssentialGraph(lock, s->map, out.problem, out.result);
  }
  out.kf_rmse_after = KeyFramePositionRmse(*s);
  out.point_rmse_after = PointRmse(*s, scene);
  return out;
}

TEST(EssentialGraphTest, MonocularLoopSpreadsTheSim3CorrectionOverTheMap) {
  const auto scene = MakeCylinderScene(3000, 3);
  LoopScenario s;
  BuildLoopScenario({}, scene, &s);
  const SE3d origin_before = s.synthetic.keyframes[0]->camera_from_world();
  const int change_before = s.map->change_index();
  const Outcome o = CloseLoop(&s, scene, PoseGraphDof::kSim3);

  // 40 keyframes, each with its parent; the loop links; covisibility.
  EXPECT_EQ(o.problem.vertices.size(), 40u);
  EXPECT_EQ(o.problem.CountEdges(EdgeKind::kSpanningTree), 39);
  EXPECT_GT(o.problem.CountEdges(EdgeKind::kNewLoop), 3);
  EXPECT_GT(o.problem.CountEdges(EdgeKind::kCovisibility), 40);
  EXPECT_EQ(o.problem.CountEdges(EdgeKind::kLoop), 0);
  EXPECT_LT(o.result.final_cost, 0.1 * o.result.initial_cost);

  // The drift is spread: keyframes and points end much closer to the truth; the origin is fixed.
  EXPECT_GT(o.kf_rmse_before, 0.2);
  EXPECT_LT(o.kf_rmse_after, 0.2 * o.kf_rmse_before);
  EXPECT_LT(o.point_rmse_after, 0.3 * o.point_rmse_before);
  EXPECT_EQ(s.synthetic.keyframes[0]->camera_from_world().Matrix(), origin_before.Matrix());
  EXPECT_EQ(s.map->change_index(), change_before + 1);
  // The Sim3 vertices did use their scale.
  double max_log_scale = 0;
  for (const auto& sim : o.result.camera_from_world) {
    max_log_scale = std::max(max_log_scale, std::abs(std::log(sim.scale())));
  }
  EXPECT_GT(max_log_scale, 0.01);
}

TEST(EssentialGraphTest, StereoLoopKeepsScalesAtOne) {
  const auto scene = MakeCylinderScene(3000, 3);
  LoopScenarioOptions options;
  options.drift_scale_per_keyframe = 1.0;
  LoopScenario s;
  BuildLoopScenario(options, scene, &s);
  const Outcome o = CloseLoop(&s, scene, PoseGraphDof::kSE3);
  for (const auto& sim : o.result.camera_from_world) EXPECT_EQ(sim.scale(), 1.0);
  EXPECT_GT(o.kf_rmse_before, 0.1);
  EXPECT_LT(o.kf_rmse_after, 0.2 * o.kf_rmse_before);
  EXPECT_LT(o.point_rmse_after, 0.3 * o.point_rmse_before);
}

TEST(EssentialGraphTest, KeyFramesAndPointsAddedAfterCollectFollowTheirAncestor) {
  const auto scene = MakeCylinderScene(3000, 3);
  LoopScenarioOptions options;
  options.drift_scale_per_keyframe = 1.0;
  LoopScenario s;
  BuildLoopScenario(options, scene, &s);
  EssentialGraphOptions eg;
  eg.dof = PoseGraphDof::kSE3;
  EssentialGraphProblem problem;
  {
    auto lock = MapReader(s.atlas).Lock();
    problem = CollectEssentialGraph(s.map, s.correction, eg);
  }
  // While the solver runs, tracking inserts a keyframe hanging from keyframe 20 and a point.
  KeyFrame* anchor = s.synthetic.keyframes[20].get();
  KeyFramePtr late;
  MapPointPtr late_point;
  const SE3d late_from_anchor(SO3d::Exp(Eigen::Vector3d(0, 0.05, 0)), Eigen::Vector3d(0.1, 0, 0));
  {
    auto lock = MapEditor(&s.atlas).Write(MapEdit::kFixture);
    std::vector<int> unused;
    Frame f = testing::MakeFrame(scene, testing::MakeStereoRig(), anchor->camera_from_world(),
                                 s.atlas.NextFrameId(), 0, {}, &unused);
    f.SetPose(late_from_anchor * anchor->camera_from_world());
    late = std::make_shared<KeyFrame>(s.atlas.NextKeyFrameId(), f, s.map);
    s.map->AddKeyFrame(lock, late);
    late->ChangeParent(lock, anchor);
    late_point = std::make_shared<MapPoint>(s.atlas.NextMapPointId(),
                                            late->world_from_camera() * Eigen::Vector3d(0, 0, 5),
                                            late.get(), s.map);
    s.map->AddMapPoint(lock, late_point);
  }
  const auto result = SolveEssentialGraph(problem, eg);
  auto lock = MapEditor(&s.atlas).Write(MapEdit::kFixture);
  ApplyEssentialGraph(lock, s.map, problem, result);
  const SE3d rel = late->camera_from_world() * anchor->world_from_camera();
  EXPECT_LT((rel.translation() - late_from_anchor.translation()).norm(), 1e-9);
  EXPECT_LT((rel.so3().Inverse() * late_from_anchor.so3()).Log().norm(), 1e-9);
  EXPECT_LT((late->camera_from_world() * late_point->position() - Eigen::Vector3d(0, 0, 5)).norm(),
            1e-9);
  // The anchor did move (the correction is not the identity there).
  EXPECT_GT(
      (anchor->CameraCenter() - problem.vertices[20].camera_from_world.Inverse().translation())
          .norm(),
      0.01);
}

TEST(EssentialGraphTest, IsDeterministic) {
  const auto scene = MakeCylinderScene(3000, 3);
  LoopScenario a, b;
  BuildLoopScenario({}, scene, &a);
  BuildLoopScenario({}, scene, &b);
  const Outcome oa = CloseLoop(&a, scene, PoseGraphDof::kSim3);
  const Outcome ob = CloseLoop(&b, scene, PoseGraphDof::kSim3);
  ASSERT_EQ(oa.result.camera_from_world.size(), ob.result.camera_from_world.size());
  for (std::size_t v = 0; v < oa.result.camera_from_world.size(); ++v) {
    EXPECT_EQ(oa.result.camera_from_world[v].Matrix(), ob.result.camera_from_world[v].Matrix());
  }
  for (std::size_t k = 0; k < a.synthetic.keyframes.size(); ++k) {
    EXPECT_EQ(a.synthetic.keyframes[k]->camera_from_world().Matrix(),
              b.synthetic.keyframes[k]->camera_from_world().Matrix());
  }
  EssentialGraphOptions bad;
  bad.iterations = 0;
  EXPECT_THROW(bad.Check(), OptionError);
}

}  // namespace
}  // namespace pkslam
