// The 4-DoF (yaw + translation) essential graph of inertial maps and its manifold.
#include <gtest/gtest.h>

#include <cmath>
#include <mutex>
#include <random>
#include <vector>

#include "estimators/optim/yaw_manifold.h"
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
using EdgeKind = EssentialGraphProblem::EdgeKind;

Eigen::Quaterniond RandomQuaternion(std::mt19937_64* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Eigen::Quaterniond(n(*rng), n(*rng), n(*rng), n(*rng)).normalized();
}

void ToBlock(const Eigen::Quaterniond& q, double* b) {
  b[0] = q.x();
  b[1] = q.y();
  b[2] = q.z();
  b[3] = q.w();
}

Eigen::Matrix3d FromBlock(const double* b) {
  return Eigen::Quaterniond(b[3], b[0], b[1], b[2]).toRotationMatrix();
}

TEST(YawQuaternionManifoldTest, TurnsOnlyAboutWorldZ) {
  std::mt19937_64 rng(7);
  const YawQuaternionManifold m;
  for (int trial = 0; trial < 20; ++trial) {
    double x[4], y[4];
    ToBlock(RandomQuaternion(&rng), x);
    const double delta = 0.3 * (trial - 10) / 10.0 + 0.05;
    ASSERT_TRUE(m.Plus(x, &delta, y));
    // camera_from_world * e_z (gravity seen from the camera) is unchanged, the yaw is delta.
    EXPECT_LT(
        (FromBlock(y) * Eigen::Vector3d::UnitZ() - FromBlock(x) * Eigen::Vector3d::UnitZ()).norm(),
        1e-12);
    const SO3d world_turn(Eigen::Matrix3d(FromBlock(y).transpose() * FromBlock(x)));
    EXPECT_NEAR(ClosestYawAngle(world_turn), -delta, 1e-12);
    double back = 0;
    ASSERT_TRUE(m.Minus(y, x, &back));
    EXPECT_NEAR(back, delta, 1e-12);
    // Jacobians: Plus against central differences; MinusJacobian * PlusJacobian = 1.
    double jp[4], jm[4], yp[4], ym[4];
    const double h = 1e-6, mh = -1e-6;
    ASSERT_TRUE(m.PlusJacobian(x, jp));
    ASSERT_TRUE(m.MinusJacobian(x, jm));
    m.Plus(x, &h, yp);
    m.Plus(x, &mh, ym);
    double dot = 0;
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(jp[k], (yp[k] - ym[k]) / (2 * h), 1e-8);
      dot += jm[k] * jp[k];
    }
    EXPECT_NEAR(dot, 1.0, 1e-12);
  }
}

TEST(YawQuaternionManifoldTest, ProjectionKeepsYawAndTheAnchor) {
  const SO3d yaw = SO3d::Exp(Eigen::Vector3d(0, 0, 0.2));
  const SO3d tilt = SO3d::Exp(Eigen::Vector3d(0.01, -0.006, 0));
  const Sim3d full(1.02, tilt * yaw, Eigen::Vector3d(0.3, -0.1, 0.05));
  const Eigen::Vector3d anchor(2.0, 1.0, 1.5);
  const Sim3d p = ProjectToYawTranslation(full, anchor);
  EXPECT_EQ(p.scale(), 1.0);
  EXPECT_LT(TiltAngle(p.so3()), 1e-12);
  EXPECT_GT(TiltAngle(full.so3()), 0.01);
  EXPECT_NEAR(ClosestYawAngle(p.so3()), 0.2, 1e-4);
  EXPECT_LT((p * anchor - full * anchor).norm(), 1e-12);
  // A yaw + translation correction is its own projection whatever the anchor.
  const Sim3d q = ProjectToYawTranslation(p, Eigen::Vector3d(-4, 3, 0.5));
  EXPECT_LT((q.Matrix() - p.Matrix()).norm(), 1e-12);
}

// Gravity seen from the camera: what a 4-DoF correction must not change.
Eigen::Vector3d GravityInCamera(const SE3d& camera_from_world) {
  return camera_from_world.so3() * Eigen::Vector3d::UnitZ();
}

struct InertialLoop {
  LoopScenario s;
  std::vector<SE3d> pose_before;  // before the loop correction (non-corrected where known)
  std::vector<Eigen::Vector3d> velocity_before;
  double kf_rmse_before = 0;
};

// The loop scenario in a gravity-aligned world (circle axis = z, drift in yaw + translation),
// an inertial chain (each keyframe after the one before, a spanning tree that skips one) and
// valid velocities. `loop_tilt` rad of roll error is put into the loop measurement.
void BuildInertialLoop(double loop_tilt, const testing::SyntheticScene& scene, InertialLoop* l) {
  LoopScenarioOptions o;
  o.drift_scale_per_keyframe = 1.0;
  o.world_from_scenario = SO3d::Exp(Eigen::Vector3d(M_PI / 2, 0, 0));  // y -> z
  BuildLoopScenario(o, scene, &l->s);
  auto lock = MapEditor(&l->s.atlas).Write(MapEdit::kFixture);
  auto& kfs = l->s.synthetic.keyframes;
  for (std::size_t k = 0; k < kfs.size(); ++k) {
    KeyFrame* kf = kfs[k].get();
    if (k > 0) kf->map()->inertial_chain().Append(lock, kfs[k - 1].get(), kf, std::nullopt);
    kf->mutable_imu(lock).state.valid = true;
    kf->mutable_imu(lock).state.velocity_world =
        Eigen::Vector3d(0.5, -0.2, 0.1 * static_cast<double>(k % 3));
    if (k >= 2) {
      kf->parent()->EraseChild(lock, kf);
      kf->ChangeParent(lock, kfs[k - 2].get());
    }
  }
  LoopCorrection& c = l->s.correction;
  const KeyFrame* current = kfs.back().get();
  const Eigen::Vector3d centre = current->CameraCenter();
  const Sim3d tilt(1.0, SO3d::Exp(Eigen::Vector3d(loop_tilt, 0.5 * loop_tilt, 0)),
                   centre - SO3d::Exp(Eigen::Vector3d(loop_tilt, 0.5 * loop_tilt, 0)) * centre);
  for (auto& [id, corrected] : c.corrected_camera_from_world)
    corrected = corrected * tilt.Inverse();
  for (const auto& kf : kfs) {
    auto it = c.non_corrected_camera_from_world.find(kf->id());
    l->pose_before.push_back(it != c.non_corrected_camera_from_world.end()
                                 ? it->second.ToSE3ScaledTranslation()
                                 : kf->camera_from_world());
    l->velocity_before.push_back(kf->imu().state.velocity_world);
  }
  lock.unlock();
  l->kf_rmse_before = KeyFramePositionRmse(l->s);
}

struct Solved {
  EssentialGraphProblem problem;
  EssentialGraphResult result;
};

Solved Close(LoopScenario* s, PoseGraphDof dof) {
  Solved out;
  EssentialGraphOptions options;
  options.dof = dof;
  {
    auto lock = MapReader(s->atlas).Lock();
    out.problem = CollectEssentialGraph(s->map, s->correction, options);
  }
  out.result = SolveEssentialGraph(out.problem, options);
  auto lock = MapEditor(&s->atlas).Write(MapEdit::kFixture);
  ApplyEssentialGraph(lock, s->map, out.problem, out.result);
  return out;
}

double MaxTiltChange(const InertialLoop& l) {
  double worst = 0;
  const auto& kfs = l.s.synthetic.keyframes;
  for (std::size_t k = 0; k < kfs.size(); ++k) {
    const Eigen::Vector3d a = GravityInCamera(l.pose_before[k]);
    const Eigen::Vector3d b = GravityInCamera(kfs[k]->camera_from_world());
    worst = std::max(worst, std::atan2(a.cross(b).norm(), a.dot(b)));
  }
  return worst;
}

TEST(EssentialGraphYawTest, InertialLoopIsCorrectedInYawAndTranslationOnly) {
  const SO3d world_from_scenario = SO3d::Exp(Eigen::Vector3d(M_PI / 2, 0, 0));
  auto scene = MakeCylinderScene(3000, 3);
  testing::RotateScene(world_from_scenario, &scene);
  InertialLoop l;
  BuildInertialLoop(0.02, scene, &l);
  const SE3d origin_before = l.s.synthetic.keyframes[0]->camera_from_world();
  const Solved o = Close(&l.s, PoseGraphDof::kYawTranslation);

  const int n = static_cast<int>(l.s.synthetic.keyframes.size());
  EXPECT_EQ(o.problem.CountEdges(EdgeKind::kSpanningTree), n - 1);
  // Every chain link except 1 -> 0, which is also the spanning-tree edge.
  EXPECT_EQ(o.problem.CountEdges(EdgeKind::kInertial), n - 2);
  EXPECT_GT(o.problem.CountEdges(EdgeKind::kNewLoop), 3);
  EXPECT_LT(o.result.final_cost, 0.1 * o.result.initial_cost);

  // The yaw + translation drift is spread; the origin stays put.
  const double kf_rmse_after = KeyFramePositionRmse(l.s);
  EXPECT_GT(l.kf_rmse_before, 0.1);
  EXPECT_LT(kf_rmse_after, 0.2 * l.kf_rmse_before);
  EXPECT_EQ(l.s.synthetic.keyframes[0]->camera_from_world().Matrix(), origin_before.Matrix());
  for (const auto& sim : o.result.camera_from_world) EXPECT_EQ(sim.scale(), 1.0);

  // Roll and pitch of every keyframe are those before the loop, although the loop measurement
  // carried a 0.02 rad tilt; velocities turned with their keyframe.
  EXPECT_LT(MaxTiltChange(l), 1e-9);
  double max_yaw = 0;
  for (int k = 0; k < n; ++k) {
    const KeyFrame* kf = l.s.synthetic.keyframes[static_cast<std::size_t>(k)].get();
    const SO3d turn =
        kf->world_from_camera().so3() * l.pose_before[static_cast<std::size_t>(k)].so3();
    max_yaw = std::max(max_yaw, std::abs(ClosestYawAngle(turn)));
    EXPECT_LT(
        (kf->imu().state.velocity_world - turn * l.velocity_before[static_cast<std::size_t>(k)])
            .norm(),
        1e-9);
  }
  EXPECT_GT(max_yaw, 0.05);  // the correction did turn the keyframes
}

TEST(EssentialGraphYawTest, TheSixDofGraphWouldTiltTheMap) {
  // The same loop through the SE3 graph: the tilt of the measurement reaches the keyframes
  // (what the 4-DoF graph exists to prevent).
  const SO3d world_from_scenario = SO3d::Exp(Eigen::Vector3d(M_PI / 2, 0, 0));
  auto scene = MakeCylinderScene(3000, 3);
  testing::RotateScene(world_from_scenario, &scene);
  InertialLoop l;
  BuildInertialLoop(0.02, scene, &l);
  const Solved o = Close(&l.s, PoseGraphDof::kSE3);
  EXPECT_EQ(o.problem.CountEdges(EdgeKind::kInertial), 0);
  EXPECT_GT(MaxTiltChange(l), 0.01);
}

}  // namespace
}  // namespace pkslam
