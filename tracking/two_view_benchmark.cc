// Speed of the monocular two-view initialisation: 1000 matches (1 px noise, optional 20%
// outliers), 200 RANSAC iterations, H and F in parallel or one after the other.
// Counters: rotation / translation-direction error (deg) and triangulated points.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "estimators/two_view/two_view_models.h"
#include "estimators/two_view/two_view_motion.h"
#include "map_model/testing/synthetic_map.h"
#include "tracking/two_view_initializer.h"

namespace pkslam {
namespace {

struct Case {
  Frame first, second;
  std::vector<int> matches12;
  SE3d camera2_from_camera1;
};

// Exactly `num_matches` matches (the first ones found) between two views of a 3-D box scene
// (or of a tilted plane).
Case MakeCase(int num_matches, double outlier_fraction, bool planar) {
  Case c;
  auto rig = testing::MakeStereoRig(Sensor::kMonocular);
  testing::SyntheticScene scene = testing::MakeScene(2000, 7, 5.0, 3.0, 3.0, 8.0);
  if (planar) {
    for (auto& p : scene.points_world) p.z() = 5.0 + 0.5 * p.x() - 0.3 * p.y();
  }
  // Planar: plane and motion chosen so that ORB-SLAM's 0.75 rule resolves the two-fold planar
  // ambiguity (it does not for some planes, e.g. z = 5 + 0.4 x + 0.2 y here; see the sweep).
  c.camera2_from_camera1 =
      planar ? SE3d(SO3d::Exp(Eigen::Vector3d(0.0, -0.05, 0.01)), Eigen::Vector3d(0.6, 0.1, 0.0))
                   .Inverse()
             : SE3d(SO3d::Exp(Eigen::Vector3d(0.01, -0.04, 0.02)), Eigen::Vector3d(0.5, 0.05, 0.1))
                   .Inverse();
  testing::FrameOptions o;
  o.pixel_noise = 1.0;
  o.stereo = false;
  std::vector<int> p1, p2;
  c.first = testing::MakeFrame(scene, rig, SE3d(), 0, 0, o, &p1);
  o.seed = 2;
  o.outlier_fraction = outlier_fraction;
  c.second = testing::MakeFrame(scene, rig, c.camera2_from_camera1, 1, 1, o, &p2);
  std::vector<int> kp2_of_point(scene.points_world.size(), -1);
  for (int i = 0; i < static_cast<int>(p2.size()); ++i) kp2_of_point[p2[i]] = i;
  c.matches12.assign(c.first.size(), -1);
  int n = 0;
  for (int i = 0; i < c.first.size() && n < num_matches; ++i) {
    c.matches12[i] = kp2_of_point[p1[i]];
    if (c.matches12[i] >= 0) ++n;
  }
  return c;
}

void BM_ReconstructTwoView(benchmark::State& state) {
  const bool parallel = state.range(0) != 0;
  const double outliers = state.range(1) / 100.0;
  const bool planar = state.range(2) != 0;
  const Case c = MakeCase(1000, outliers, planar);
  TwoViewOptions options;
  options.iterations = 200;
  options.parallel = parallel;
  std::optional<TwoViewResult> result;
  TwoViewReport report;
  for (auto _ : state) {
    result = ReconstructTwoView(c.first, c.second, c.matches12, options, &report);
    benchmark::DoNotOptimize(result);
  }
  if (!result) {
    state.SkipWithError(ToString(report.rejection));
    return;
  }
  const SE3d delta = result->camera2_from_camera1 * c.camera2_from_camera1.Inverse();
  const Eigen::Vector3d t_true = c.camera2_from_camera1.translation().normalized();
  state.counters["rot_err_deg"] = delta.so3().Log().norm() * 180.0 / M_PI;
  state.counters["trans_err_deg"] =
      std::acos(std::min(1.0, t_true.dot(result->camera2_from_camera1.translation()))) * 180.0 /
      M_PI;
  state.counters["triangulated"] = result->num_triangulated;
  state.counters["homography"] = result->used_homography;
}
BENCHMARK(BM_ReconstructTwoView)
    ->ArgNames({"parallel", "outlier_pct", "planar"})
    ->Args({1, 0, 0})
    ->Args({0, 0, 0})
    ->Args({1, 20, 0})
    ->Args({1, 0, 1})
    ->Unit(benchmark::kMillisecond);

// The pieces: RANSAC of each model alone, and one motion check over all pairs.
void BM_RansacModels(benchmark::State& state) {
  const bool homography = state.range(0) != 0;
  const Case c = MakeCase(1000, 0.0, false);
  two_view::Correspondences pixels;
  for (int i = 0; i < c.first.size(); ++i) {
    if (c.matches12[i] < 0) continue;
    const auto& a = c.first.keypoints_undistorted()[i].pt;
    const auto& b = c.second.keypoints_undistorted()[c.matches12[i]].pt;
    pixels.first.emplace_back(a.x, a.y);
    pixels.second.emplace_back(b.x, b.y);
  }
  std::vector<two_view::MinimalSet> sets(200);
  for (int k = 0; k < 200; ++k) {
    for (int j = 0; j < two_view::kMinimalSetSize; ++j) sets[k][j] = (k * 97 + j * 131) % 1000;
  }
  two_view::RansacOptions options;
  options.refine_iterations = static_cast<int>(state.range(1));
  options.reject_degenerate_samples = state.range(2) != 0;
  const auto n1 = two_view::NormalizePoints(pixels.first);
  const auto n2 = two_view::NormalizePoints(pixels.second);
  for (auto _ : state) {
    auto fit = homography ? two_view::RansacHomography(pixels, n1, n2, sets, options)
                          : two_view::RansacFundamental(pixels, n1, n2, sets, options);
    benchmark::DoNotOptimize(fit);
  }
}
BENCHMARK(BM_RansacModels)
    ->ArgNames({"homography", "refine", "degeneracy_test"})
    ->Args({0, 0, 0})
    ->Args({0, 5, 0})
    ->Args({0, 5, 1})
    ->Args({1, 0, 0})
    ->Args({1, 5, 0})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace pkslam

namespace pkslam {
namespace {

two_view::Correspondences RandomPairs(int n) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 700);
  two_view::Correspondences c;
  for (int i = 0; i < n; ++i) {
    c.first.emplace_back(u(rng), u(rng) * 0.65);
    c.second.emplace_back(c.first.back() + Eigen::Vector2d(20 + u(rng) * 0.01, u(rng) * 0.01));
  }
  return c;
}

void BM_MinimalFits(benchmark::State& state) {
  const two_view::Correspondences c = RandomPairs(8);
  for (auto _ : state) {
    Eigen::Matrix3d m = state.range(0) ? two_view::ComputeHomographyDlt(c.first, c.second)
                                       : two_view::ComputeFundamentalEightPoint(c.first, c.second);
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_MinimalFits)->ArgName("homography")->Arg(0)->Arg(1);

void BM_CheckMotion(benchmark::State& state) {
  const two_view::Correspondences c = RandomPairs(1000);
  two_view::Correspondences normalized;
  const two_view::Pinhole cam{435, 435, 367, 248};
  for (int i = 0; i < c.size(); ++i) {
    normalized.first.push_back(cam.Normalize(c.first[i]));
    normalized.second.push_back(cam.Normalize(c.second[i]));
  }
  const std::vector<std::uint8_t> all(c.size(), 1);
  const two_view::Motion m{Eigen::Matrix3d::Identity(), Eigen::Vector3d(-1, 0, 0)};
  for (auto _ : state) {
    auto check = two_view::CheckMotion(m, c, normalized, all, cam, cam, 4.0);
    benchmark::DoNotOptimize(check);
  }
}
BENCHMARK(BM_CheckMotion)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace pkslam
