// The front end at the image sizes of the datasets people run: EuRoC (752x480, 1200 ORB
// features in ORB-SLAM3's stereo settings), TUM RGB-D (640x480, 1000) and KITTI odometry
// (1241x376, 2000). Stages: ORB extraction on one core and with the helper thread that takes
// pyramid levels (the second core), and whole frame building (monocular: extraction,
// undistortion, grid; stereo: both images concurrently + stereo matching).
//
// Images: a deterministic synthetic texture (corners at all scales) of the size; the right
// image is the left one shifted by 12 px (a fronto-parallel wall), so stereo matching finds
// real matches. Counters: median_ms (wall, per call), cpu_ms (process CPU, all threads, per
// call), features (keypoints per image).
//   build/benchmarks/pkslam_tracking_benchmark --benchmark_filter=FrontEnd
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

#include "core/features/orb_extractor.h"
#include "core/features/synthetic_texture.h"
#include "core/sensor/camera_rig.h"
#include "core/util/cpu_time.h"
#include "core/util/quantile.h"
#include "tracking/frame_builder.h"

namespace pkslam {
namespace {

struct ImageSize {
  const char* name;
  int width;
  int height;
  int features;
  double fx;
};

// Indexed by the benchmarks' first argument.
constexpr ImageSize kSizes[] = {
    {"euroc", 752, 480, 1200, 458.654},
    {"tum", 640, 480, 1000, 525.0},
    {"kitti", 1241, 376, 2000, 718.856},
};

double Median(std::vector<double> v) { return Quantile(std::move(v), 0.5).value_or(0.0); }

OrbOptions OrbFor(const ImageSize& size, bool parallel) {
  OrbOptions o;
  o.n_features = size.features;
  o.n_levels = 8;
  o.scale_factor = 1.2;
  o.ini_th_fast = 20;
  o.min_th_fast = 7;
  o.parallel = parallel;
  return o;
}

// An ideal (rectified) pinhole rig of the size with a 0.11 m baseline.
std::shared_ptr<const CameraRig> RigFor(const ImageSize& size, Sensor sensor) {
  auto rig = std::make_shared<CameraRig>();
  rig->sensor = sensor;
  rig->camera = CameraModel::Pinhole(size.width, size.height, size.fx, size.fx,
                                     0.5 * (size.width - 1), 0.5 * (size.height - 1));
  rig->baseline = 0.11;
  rig->bf = size.fx * rig->baseline;
  rig->th_depth = 35.0 * rig->baseline;
  rig->pyramid = ScalePyramid(8, 1.2);
  rig->UpdateDerived();
  return rig;
}

struct Pair {
  cv::Mat left;
  cv::Mat right;
};

Pair ImagesFor(const ImageSize& size) {
  Pair p;
  p.left = SyntheticTexture(cv::Size(size.width, size.height), 7);
  const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, -12, 0, 1, 0);
  cv::warpAffine(p.left, p.right, shift, p.left.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return p;
}

// Times `call` (returns the keypoint count) per iteration; median wall and CPU as counters.
template <typename Call>
void Measure(benchmark::State& state, const ImageSize& size, Call&& call) {
  std::vector<double> wall_ms;
  std::vector<double> cpu_ms;
  double features = 0.0;
  for (auto _ : state) {
    const double c0 = ProcessCpuMs();
    const auto t0 = std::chrono::steady_clock::now();
    features += static_cast<double>(call());
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.SetIterationTime(s);
    wall_ms.push_back(1e3 * s);
    cpu_ms.push_back(ProcessCpuMs() - c0);
  }
  state.SetLabel(size.name);
  state.counters["median_ms"] = Median(wall_ms);
  state.counters["cpu_ms"] = Median(cpu_ms);
  state.counters["features"] =
      features / static_cast<double>(std::max<std::size_t>(wall_ms.size(), 1));
}

// Arguments: size index, parallel (0: one core, 1: the helper thread takes levels).
void BM_FrontEnd_OrbExtract(benchmark::State& state) {
  const ImageSize& size = kSizes[state.range(0)];
  const OrbExtractor extractor(OrbFor(size, state.range(1) != 0));
  const cv::Mat image = ImagesFor(size).left;
  OrbFeatures features;
  Measure(state, size, [&] {
    extractor.Extract(image, &features);
    return features.keypoints.size();
  });
}
BENCHMARK(BM_FrontEnd_OrbExtract)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->ArgNames({"size", "parallel"})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

void BM_FrontEnd_BuildMonocular(benchmark::State& state) {
  const ImageSize& size = kSizes[state.range(0)];
  const FrameBuilder builder(RigFor(size, Sensor::kMonocular), OrbFor(size, true));
  const cv::Mat image = ImagesFor(size).left;
  FrameId id = 0;
  Measure(state, size, [&] { return builder.BuildMonocular(id++, 0, image).size(); });
}
BENCHMARK(BM_FrontEnd_BuildMonocular)
    ->DenseRange(0, 2)
    ->ArgName("size")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

// Arguments: size index, parallel (0: the two images one after the other on one core).
void BM_FrontEnd_BuildStereo(benchmark::State& state) {
  const ImageSize& size = kSizes[state.range(0)];
  const FrameBuilder builder(RigFor(size, Sensor::kStereo), OrbFor(size, state.range(1) != 0));
  const Pair images = ImagesFor(size);
  FrameId id = 0;
  int matched = 0;
  int frames = 0;
  Measure(state, size, [&] {
    const Frame f = builder.BuildStereo(id++, 0, images.left, images.right);
    matched += static_cast<int>(
        std::count_if(f.depth().begin(), f.depth().end(), [](float d) { return d > 0; }));
    ++frames;
    return f.size();
  });
  state.counters["stereo_matched"] = frames > 0 ? static_cast<double>(matched) / frames : 0.0;
}
BENCHMARK(BM_FrontEnd_BuildStereo)
    ->ArgsProduct({{0, 1, 2}, {0, 1}})
    ->ArgNames({"size", "parallel"})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace pkslam
