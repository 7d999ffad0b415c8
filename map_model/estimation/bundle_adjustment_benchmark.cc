// Local bundle adjustment on synthetic maps of ORB-SLAM-like local-BA size (all keyframes
// covisible; the origin is the fixed gauge), 1 px noise and 2% outlier keypoints, started from
// a perturbation (1 cm / 0.2 degrees per free keyframe, 1 cm per point).
//   build/benchmarks/pkslam_map_model_benchmark --benchmark_filter=Bundle
// Args: keyframes, scene points (about 3/4 become map points). Counters: kf = keyframes,
// pts = map points, obs = observations, it = solver iterations of both passes.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <memory>
#include <mutex>
#include <random>
#include <shared_mutex>

#include "estimators/optim/bundle_adjustment_internal.h"
#include "map_model/estimation/bundle_collect.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

struct LocalMap {
  Atlas atlas;
  testing::SyntheticMap map;
};

// Built in each benchmark function before its timed loop (Google Benchmark calls the function
// a few times while calibrating; the build is never timed).
std::unique_ptr<LocalMap> BuildMap(int keyframes, int points, bool stereo) {
  auto m = std::make_unique<LocalMap>();
  auto rig = testing::MakeStereoRig(stereo ? Sensor::kStereo : Sensor::kMonocular);
  // A wide scene so that each point is seen by about half of the keyframes (for up to 20
  // keyframes); longer paths get a scene stretched along them.
  const double half_path = 0.5 * 0.45 * keyframes;
  auto scene = testing::MakeScene(points, 31, std::max(6.0, half_path + 3.0), 3.0, 3.0, 9.0);
  if (keyframes > 20) {
    for (auto& p : scene.points_world) p.x() += half_path;
  }
  const auto poses = testing::MakeForwardPath(keyframes, 0.45, 32);
  testing::FrameOptions o;
  o.stereo = stereo;
  o.pixel_noise = 1.0;
  o.outlier_fraction = 0.02;
  m->map = testing::MakeMap(&m->atlas, scene, rig, poses, o);
  return m;
}

BundleProblem Perturbed(BundleProblem problem) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (auto& k : problem.keyframes) {
    if (k.fixed) continue;
    Eigen::Matrix<double, 6, 1> d;
    d << 0.01 * u(rng), 0.01 * u(rng), 0.01 * u(rng), 0.0035 * u(rng), 0.0035 * u(rng),
        0.0035 * u(rng);
    k.camera_from_world = SE3d::Exp(d) * k.camera_from_world;
  }
  for (auto& p : problem.points) p.position_world += 0.01 * Eigen::Vector3d(u(rng), u(rng), u(rng));
  return problem;
}

BundleProblem Collect(LocalMap& m) {
  auto lock = MapReader(m.atlas).Lock();
  return CollectLocalBundle(lock, m.map.keyframes.back().get(), {});
}

void SetCounters(benchmark::State& state, const BundleProblem& p, int iterations) {
  state.counters["kf"] = static_cast<double>(p.keyframes.size());
  state.counters["pts"] = static_cast<double>(p.points.size());
  state.counters["obs"] = static_cast<double>(p.observations.size());
  state.counters["it"] = iterations;
}

// Args: keyframes, scene points, stereo (0/1), solver (0 = SPARSE_SCHUR, 1 = DENSE_SCHUR).
void BM_SolveLocalBundle(benchmark::State& state) {
  const auto m = BuildMap(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)),
                          state.range(2) != 0);
  const BundleProblem problem = Perturbed(Collect(*m));
  internal::BundleSolverOverrides overrides;
  overrides.linear_solver = state.range(3) == 0 ? ceres::SPARSE_SCHUR : ceres::DENSE_SCHUR;
  int iterations = 0;
  for (auto _ : state) {
    const BundleResult r = internal::SolveBundle(problem, {}, nullptr, overrides);
    iterations = r.iterations;
    benchmark::DoNotOptimize(r.final_cost);
  }
  SetCounters(state, problem, iterations);
}
BENCHMARK(BM_SolveLocalBundle)
    ->ArgNames({"kf", "scene", "stereo", "dense"})
    ->Args({15, 4000, 1, 0})
    ->Args({15, 4000, 1, 1})
    ->Args({15, 4000, 0, 0})
    ->Args({15, 4000, 0, 1})
    ->Args({10, 2000, 1, 0})
    ->Args({10, 2000, 1, 1})
    ->Args({20, 6500, 1, 0})
    ->Args({20, 6500, 1, 1})
    ->Unit(benchmark::kMillisecond);

// Global BA (every keyframe free but the origin), where the reduced camera system grows.
// Args: keyframes, scene points, solver (0 = SPARSE_SCHUR, 1 = DENSE_SCHUR).
void BM_SolveGlobalBundle(benchmark::State& state) {
  const auto m = BuildMap(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), true);
  BundleProblem problem;
  {
    auto lock = MapReader(m->atlas).Lock();
    problem = Perturbed(CollectGlobalBundle(lock, *m->atlas.current_map()));
  }
  internal::BundleSolverOverrides overrides;
  overrides.linear_solver = state.range(2) == 0 ? ceres::SPARSE_SCHUR : ceres::DENSE_SCHUR;
  int iterations = 0;
  for (auto _ : state) {
    const BundleResult r = internal::SolveBundle(problem, {}, nullptr, overrides);
    iterations = r.iterations;
    benchmark::DoNotOptimize(r.final_cost);
  }
  SetCounters(state, problem, iterations);
}
BENCHMARK(BM_SolveGlobalBundle)
    ->ArgNames({"kf", "scene", "dense"})
    ->Args({40, 8000, 0})
    ->Args({40, 8000, 1})
    ->Args({80, 12000, 0})
    ->Args({80, 12000, 1})
    ->Unit(benchmark::kMillisecond);

void BM_CollectLocalBundle(benchmark::State& state) {
  const auto m = BuildMap(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), true);
  BundleProblem problem;
  for (auto _ : state) {
    problem = Collect(*m);
    benchmark::DoNotOptimize(problem.observations.data());
  }
  SetCounters(state, problem, 0);
}
BENCHMARK(BM_CollectLocalBundle)->Args({15, 4000})->Unit(benchmark::kMillisecond);

// Applying the same result repeatedly: the first iteration also erases the outlier
// observations, the others measure the write-back (poses, positions, normals).
void BM_ApplyBundle(benchmark::State& state) {
  const auto m = BuildMap(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), true);
  const BundleProblem problem = Collect(*m);
  const BundleResult result = SolveBundle(Perturbed(problem), {});
  for (auto _ : state) {
    auto lock = MapEditor(&m->atlas).Write(MapEdit::kFixture);
    ApplyBundle(lock, m->atlas.current_map(), problem, result);
  }
  SetCounters(state, problem, result.iterations);
}
BENCHMARK(BM_ApplyBundle)->Args({15, 4000})->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace pkslam
