// Pose-only optimisation (4 rounds x 10 iterations) on synthetic frames with a given number of
// correspondences, 1 px noise and 10% outliers, from a pose 10 cm / 3 degrees off.
//   build/benchmarks/pkslam_tracking_benchmark --benchmark_filter=OptimizePose
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"
#include "tracking/pose_optimizer.h"

namespace pkslam {
namespace {

Frame MakeBenchmarkFrame(int correspondences, bool stereo) {
  auto rig = testing::MakeStereoRig();
  const auto scene = testing::MakeScene(3000, 5);
  testing::FrameOptions o;
  o.stereo = stereo;
  o.pixel_noise = 1.0;
  o.outlier_fraction = 0.1;
  std::vector<int> point_of_keypoint;
  const SE3d truth;
  Frame frame = testing::MakeFrame(scene, rig, truth, 1, 0, o, &point_of_keypoint);
  for (int i = 0; i < frame.size() && i < correspondences; ++i) {
    frame.map_points[i] =
        std::make_shared<MapPoint>(i, scene.points_world[point_of_keypoint[i]], nullptr, nullptr);
  }
  Eigen::Matrix<double, 6, 1> delta;
  delta << 0.06, -0.05, 0.06, 0.03, -0.03, 0.02;
  frame.SetPose(SE3d::Exp(delta) * truth);
  return frame;
}

void BM_OptimizePose(benchmark::State& state) {
  const bool stereo = state.range(1) != 0;
  const Frame original = MakeBenchmarkFrame(static_cast<int>(state.range(0)), stereo);
  int inliers = 0;
  for (auto _ : state) {
    state.PauseTiming();
    Frame frame = original;
    state.ResumeTiming();
    inliers = OptimizePose(&frame);
    benchmark::DoNotOptimize(inliers);
  }
  state.counters["inliers"] = inliers;
}
BENCHMARK(BM_OptimizePose)
    ->ArgNames({"n", "stereo"})
    ->Args({400, 1})
    ->Args({800, 1})
    ->Args({400, 0})
    ->Args({800, 0})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace pkslam
