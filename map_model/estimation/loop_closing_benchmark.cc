// Speed and accuracy of the relocalisation / loop-closing building blocks on synthetic data:
// keyframe-database queries, Sim3 RANSAC, OptimizeSim3, PnP RANSAC (ours and OpenGV's
// sac::Ransac) and the essential graph. Accuracy is reported as counters (mean over runs).
#include <benchmark/benchmark.h>

#include <cmath>
#include <mutex>

#include "core/bow/bow_test_utils.h"
#include "estimators/optim/sim3_optimization.h"
#include "estimators/ransac/pnp_test_data.h"
#include "estimators/ransac/sim3_test_data.h"
#include "map_model/estimation/essential_graph_collect.h"
#include "map_model/keyframe_database.h"
#include "map_model/keyframe_database_test_utils.h"
#include "map_model/map_editor.h"
#include "map_model/testing/loop_scenario.h"

namespace pkslam {
namespace {

double RotationErrorDeg(const SO3d& a, const SO3d& b) {
  return (a.Inverse() * b).Log().norm() * 180.0 / M_PI;
}

// Relocalisation query over a 200-keyframe map (10^4-word vocabulary, ~650 features).
void BM_KeyFrameDatabase_Relocalisation(benchmark::State& state) {
  const Vocabulary vocabulary = testing::MakeRandomVocabulary(10, 4, 5);
  const auto rig = testing::MakeStereoRig();
  const auto scene = testing::MakeScene(40000, 11, 300.0, 2.5, 4.0, 8.0);
  Atlas atlas;
  Map* map = nullptr;
  {
    auto lock = MapReader(atlas).Lock();
    map = atlas.current_map();
  }
  const auto kfs =
      testing::AddKeyFrames(&atlas, map, scene, rig, testing::Strip(-290, 2.9, 200), vocabulary, 1);
  KeyFrameDatabase db(vocabulary);
  auto lock = MapEditor(&atlas).Write(MapEdit::kFixture);
  for (const auto& kf : kfs) db.Add(lock, kf.get());
  testing::FrameOptions fo;
  fo.descriptor_bit_flips = 2;
  std::vector<int> unused;
  Frame query = testing::MakeFrame(scene, rig, SE3d(SO3d(), Eigen::Vector3d(0.5, 0, 0)).Inverse(),
                                   7, 0, fo, &unused);
  query.ComputeBoW(vocabulary);
  std::size_t found = 0;
  for (auto _ : state) {
    const auto candidates = db.DetectRelocalisationCandidates(query, map);
    found += candidates.size();
    benchmark::DoNotOptimize(candidates.data());
  }
  state.counters["candidates"] =
      static_cast<double>(found) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_KeyFrameDatabase_Relocalisation)->Unit(benchmark::kMicrosecond);

// Sim3 RANSAC to acceptance; arg = outlier percentage. Monocular (free scale 1.2).
void BM_Sim3Solver(benchmark::State& state) {
  testing::Sim3ProblemOptions po;
  po.outlier_fraction = static_cast<double>(state.range(0)) / 100.0;
  const testing::Sim3Problem p = testing::MakeSim3Problem(po);
  double rot = 0, scale = 0, iterations = 0, found = 0;
  std::uint64_t seed = 0;
  for (auto _ : state) {
    Sim3SolverOptions options;
    options.seed = seed++;
    Sim3Solver solver(p.matches, p.camera, p.camera, options);
    const auto r = solver.Iterate(300);
    iterations += solver.iterations_done();
    if (!r.found) continue;
    found += 1;
    rot += RotationErrorDeg(r.camera1_from_camera2.so3(), p.camera1_from_camera2.so3());
    scale += std::abs(r.camera1_from_camera2.scale() / p.camera1_from_camera2.scale() - 1);
  }
  state.counters["found"] = found / static_cast<double>(state.iterations());
  state.counters["rot_err_deg"] = rot / std::max(found, 1.0);
  state.counters["scale_err"] = scale / std::max(found, 1.0);
  state.counters["iterations"] = iterations / static_cast<double>(state.iterations());
  state.counters["matches"] = static_cast<double>(p.matches.size());
}
BENCHMARK(BM_Sim3Solver)->Arg(30)->Arg(50)->Unit(benchmark::kMicrosecond);

// OptimizeSim3 from the RANSAC model (seed 0), 30% outliers.
void BM_OptimizeSim3(benchmark::State& state) {
  testing::Sim3ProblemOptions po;
  po.outlier_fraction = 0.3;
  const testing::Sim3Problem p = testing::MakeSim3Problem(po);
  Sim3Solver solver(p.matches, p.camera, p.camera, Sim3SolverOptions{});
  const auto initial = solver.Iterate(300);
  if (!initial.found) {
    state.SkipWithError("RANSAC failed");
    return;
  }
  Sim3OptimizationResult r;
  for (auto _ : state) {
    r = OptimizeSim3(p.matches, p.camera, p.camera, initial.camera1_from_camera2, {});
    benchmark::DoNotOptimize(r.num_inliers);
  }
  state.counters["ransac_rot_err_deg"] =
      RotationErrorDeg(initial.camera1_from_camera2.so3(), p.camera1_from_camera2.so3());
  state.counters["ransac_scale_err"] =
      std::abs(initial.camera1_from_camera2.scale() / p.camera1_from_camera2.scale() - 1);
  state.counters["rot_err_deg"] =
      RotationErrorDeg(r.camera1_from_camera2.so3(), p.camera1_from_camera2.so3());
  state.counters["scale_err"] =
      std::abs(r.camera1_from_camera2.scale() / p.camera1_from_camera2.scale() - 1);
  state.counters["inliers"] = r.num_inliers;
  state.counters["matches"] = static_cast<double>(p.matches.size());
}
BENCHMARK(BM_OptimizeSim3)->Unit(benchmark::kMicrosecond);

template <bool kOpenGvRansac>
void BM_Pnp(benchmark::State& state) {
  const testing::PnpProblem p =
      testing::MakePnpProblem(static_cast<double>(state.range(0)) / 100.0, 1.0, 3);
  double rot = 0, centre = 0, found = 0;
  std::uint64_t seed = 0;
  for (auto _ : state) {
    PnpRansacOptions options;
    options.seed = seed++;
    PnpResult r;
    if (kOpenGvRansac) {
      r = SolvePnpOpenGvRansac(p.correspondences, p.camera, std::sqrt(5.991), options);
    } else {
      PnpRansac ransac(p.correspondences, p.camera, options);
      r = ransac.Iterate(300);
    }
    if (!r.found) continue;
    found += 1;
    rot += RotationErrorDeg(r.camera_from_world.so3(), p.camera_from_world.so3());
    centre +=
        (r.camera_from_world.Inverse().translation() - p.camera_from_world.Inverse().translation())
            .norm();
  }
  state.counters["found"] = found / static_cast<double>(state.iterations());
  state.counters["rot_err_deg"] = rot / std::max(found, 1.0);
  state.counters["centre_err_m"] = centre / std::max(found, 1.0);
  state.counters["matches"] = static_cast<double>(p.correspondences.size());
}
BENCHMARK(BM_Pnp<false>)->Name("BM_PnpRansac")->Arg(20)->Arg(45)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Pnp<true>)
    ->Name("BM_PnpOpenGvRansac")
    ->Arg(20)
    ->Arg(45)
    ->Unit(benchmark::kMicrosecond);

// Essential graph on the loop scenario (+4 keyframes revisiting the start). Timed:
// Collect + Solve; Apply once afterwards for the accuracy counters.
// Times Collect + Solve of the scenario's essential graph, then applies it once and reports the
// keyframe error before/after, the edge count and the iterations.
void TimeEssentialGraph(benchmark::State& state, testing::LoopScenario* s,
                        const EssentialGraphOptions& options) {
  EssentialGraphProblem problem;
  EssentialGraphResult result;
  for (auto _ : state) {
    {
      auto lock = MapReader(s->atlas).Lock();
      problem = CollectEssentialGraph(s->map, s->correction, options);
    }
    result = SolveEssentialGraph(problem, options);
  }
  state.counters["kf_rmse_before"] = testing::KeyFramePositionRmse(*s);
  {
    auto lock = MapEditor(&s->atlas).Write(MapEdit::kFixture);
    ApplyEssentialGraph(lock, s->map, problem, result);
  }
  state.counters["kf_rmse_after"] = testing::KeyFramePositionRmse(*s);
  state.counters["edges"] = static_cast<double>(problem.edges.size());
  state.counters["lm_iterations"] = result.iterations;
}

void BM_EssentialGraph(benchmark::State& state) {
  testing::LoopScenarioOptions o;
  o.keyframes_per_lap = static_cast<int>(state.range(0));
  o.drift_yaw_per_keyframe = 0.144 / o.keyframes_per_lap;  // same drift per lap
  o.drift_scale_per_keyframe = std::pow(1.144, 1.0 / o.keyframes_per_lap);
  o.drift_step_per_keyframe = 0.072 / o.keyframes_per_lap;
  const auto scene = testing::MakeCylinderScene(3000, 3);
  testing::LoopScenario s;
  testing::BuildLoopScenario(o, scene, &s);
  EssentialGraphOptions options;
  options.exact_log = state.range(1) != 0;
  TimeEssentialGraph(state, &s, options);
}
// args: keyframes per lap, exact Sim3 log (1) or decoupled error (0).
BENCHMARK(BM_EssentialGraph)
    ->Args({36, 1})
    ->Args({36, 0})
    ->Args({180, 1})
    ->Args({180, 0})
    ->Unit(benchmark::kMillisecond);

// The 4-DoF (yaw + translation) graph of inertial maps on the same loop in a gravity-aligned
// world (the circle's axis is z), scale drift 0, with the temporal chain's edges.
void BM_EssentialGraphYawTranslation(benchmark::State& state) {
  testing::LoopScenarioOptions o;
  o.keyframes_per_lap = static_cast<int>(state.range(0));
  o.drift_yaw_per_keyframe = 0.144 / o.keyframes_per_lap;
  o.drift_scale_per_keyframe = 1.0;
  o.drift_step_per_keyframe = 0.072 / o.keyframes_per_lap;
  o.world_from_scenario = SO3d::Exp(Eigen::Vector3d(M_PI / 2, 0, 0));
  auto scene = testing::MakeCylinderScene(3000, 3);
  testing::RotateScene(o.world_from_scenario, &scene);
  testing::LoopScenario s;
  testing::BuildLoopScenario(o, scene, &s);
  {
    auto lock = MapEditor(&s.atlas).Write(MapEdit::kFixture);
    for (std::size_t k = 1; k < s.synthetic.keyframes.size(); ++k) {
      s.synthetic.keyframes[0]->map()->inertial_chain().Append(
          lock, s.synthetic.keyframes[k - 1].get(), s.synthetic.keyframes[k].get(), std::nullopt);
    }
  }
  EssentialGraphOptions options;
  options.dof = PoseGraphDof::kYawTranslation;
  TimeEssentialGraph(state, &s, options);
}
BENCHMARK(BM_EssentialGraphYawTranslation)->Arg(36)->Arg(180)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace pkslam
