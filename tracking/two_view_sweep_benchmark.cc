// Accuracy and outcome sweep of the two-view initialisation over random scenes and motions
// (20 per configuration, 1 px noise): success / homography rates, median and worst
// rotation and translation-direction errors (deg), median relative point error after the
// best scale. One iteration each; run with
//   build/benchmarks/pkslam_tracking_benchmark --benchmark_filter=Sweep
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <string>

#include "core/util/quantile.h"
#include "estimators/two_view/two_view_refine.h"
#include "map_model/testing/synthetic_map.h"
#include "tracking/two_view_initializer.h"

namespace pkslam {
namespace {

enum SceneKind { kBox = 0, kPlane = 1, kRotation = 2 };

void BM_TwoViewSweep(benchmark::State& state) {
  const auto kind = static_cast<SceneKind>(state.range(0));
  const double baseline = state.range(1) / 100.0;
  const double outliers = state.range(2) / 100.0;
  constexpr int kTrials = 20;
  auto rig = testing::MakeStereoRig(Sensor::kMonocular);
  int accepted = 0, homography = 0;
  std::map<int, int> rejections;
  std::vector<double> rot, trans, points, oracle_trans;
  for (auto _ : state) {
    for (int trial = 0; trial < kTrials; ++trial) {
      std::mt19937_64 rng(1000 + trial);
      std::uniform_real_distribution<double> u(-1, 1);
      testing::SyntheticScene scene = testing::MakeScene(1500, 50 + trial, 5.0, 3.0, 3.0, 8.0);
      if (kind == kPlane) {
        const double gx = 0.4 * u(rng), gy = 0.4 * u(rng);
        for (auto& p : scene.points_world) p.z() = 5.0 + gx * p.x() + gy * p.y();
      }
      // Mostly sideways motion, a few degrees of rotation.
      const Eigen::Vector3d direction =
          Eigen::Vector3d(1.0, 0.3 * u(rng), 0.3 * u(rng)).normalized() * (u(rng) < 0 ? -1 : 1);
      const Eigen::Vector3d position =
          kind == kRotation ? Eigen::Vector3d::Zero() : Eigen::Vector3d(baseline * direction);
      const Eigen::Vector3d angles(0.03 * u(rng), 0.05 * u(rng), 0.03 * u(rng));
      const SE3d camera2_from_camera1 = SE3d(SO3d::Exp(angles), position).Inverse();
      testing::FrameOptions o;
      o.pixel_noise = 1.0;
      o.stereo = false;
      o.seed = 10 + trial;
      std::vector<int> p1, p2;
      const Frame f1 = testing::MakeFrame(scene, rig, SE3d(), 0, 0, o, &p1);
      o.seed = 100 + trial;
      o.outlier_fraction = outliers;
      const Frame f2 = testing::MakeFrame(scene, rig, camera2_from_camera1, 1, 1, o, &p2);
      std::vector<int> kp2(scene.points_world.size(), -1);
      for (int i = 0; i < static_cast<int>(p2.size()); ++i) kp2[p2[i]] = i;
      std::vector<int> matches(f1.size(), -1);
      for (int i = 0; i < f1.size(); ++i) matches[i] = kp2[p1[i]];
      // Oracle: the Sampson-optimal motion started from the truth on the true matches (the
      // noise floor of the translation direction for this scene).
      if (kind != kRotation) {
        two_view::Correspondences normalized;
        std::vector<std::uint8_t> mask;
        const two_view::Pinhole cam{rig->fx, rig->fy, rig->cx, rig->cy};
        for (int i = 0; i < f1.size(); ++i) {
          if (matches[i] < 0) continue;
          const auto& a = f1.keypoints_undistorted()[i].pt;
          const auto& b = f2.keypoints_undistorted()[matches[i]].pt;
          normalized.first.push_back(cam.Normalize(Eigen::Vector2d(a.x, a.y)));
          normalized.second.push_back(cam.Normalize(Eigen::Vector2d(b.x, b.y)));
          const auto uv = rig->camera.Project(camera2_from_camera1 * scene.points_world[p1[i]]);
          mask.push_back(uv && (*uv - Eigen::Vector2d(b.x, b.y)).norm() < 5.0);
        }
        const two_view::Motion truth{camera2_from_camera1.RotationMatrix(),
                                     camera2_from_camera1.translation().normalized()};
        const auto oracle = two_view::RefineMotion(truth, normalized, mask, 20);
        oracle_trans.push_back(
            std::acos(std::clamp(oracle.motion.translation.dot(truth.translation), -1.0, 1.0)) *
            180.0 / M_PI);
      }
      TwoViewOptions options;
      options.seed = trial;
      TwoViewReport report;
      const auto r = ReconstructTwoView(f1, f2, matches, options, &report);
      ++rejections[static_cast<int>(report.rejection)];
      if (!r) continue;
      ++accepted;
      homography += r->used_homography;
      if (kind == kRotation) continue;
      const SE3d delta = r->camera2_from_camera1 * camera2_from_camera1.Inverse();
      rot.push_back(delta.so3().Log().norm() * 180.0 / M_PI);
      const Eigen::Vector3d t_true = camera2_from_camera1.translation().normalized();
      trans.push_back(
          std::acos(std::clamp(t_true.dot(r->camera2_from_camera1.translation()), -1.0, 1.0)) *
          180.0 / M_PI);
      double num = 0, den = 0;
      for (int i = 0; i < f1.size(); ++i) {
        if (!r->triangulated[i]) continue;
        num += r->points[i].dot(scene.points_world[p1[i]]);
        den += r->points[i].squaredNorm();
      }
      std::vector<double> rel;
      for (int i = 0; i < f1.size(); ++i) {
        if (!r->triangulated[i]) continue;
        const Eigen::Vector3d& truth = scene.points_world[p1[i]];
        rel.push_back((num / den * r->points[i] - truth).norm() / truth.norm());
      }
      points.push_back(Quantile(rel, 0.5).value_or(0.0));
    }
  }
  state.counters["accepted"] = static_cast<double>(accepted) / kTrials;
  for (const auto& [reason, count] : rejections) {
    if (reason == static_cast<int>(TwoViewRejection::kNone)) continue;
    std::string name = ToString(static_cast<TwoViewRejection>(reason));
    std::replace(name.begin(), name.end(), ' ', '_');
    state.counters["no:" + name] = count;
  }
  state.counters["homography"] = static_cast<double>(homography) / kTrials;
  state.counters["rot_med_deg"] = Quantile(rot, 0.5).value_or(0.0);
  state.counters["rot_max_deg"] = rot.empty() ? 0 : *std::max_element(rot.begin(), rot.end());
  state.counters["trans_med_deg"] = Quantile(trans, 0.5).value_or(0.0);
  state.counters["trans_max_deg"] =
      trans.empty() ? 0 : *std::max_element(trans.begin(), trans.end());
  state.counters["point_err_med"] = Quantile(points, 0.5).value_or(0.0);
  state.counters["oracle_trans_med_deg"] = Quantile(oracle_trans, 0.5).value_or(0.0);
  state.counters["oracle_trans_max_deg"] =
      oracle_trans.empty() ? 0 : *std::max_element(oracle_trans.begin(), oracle_trans.end());
}
BENCHMARK(BM_TwoViewSweep)
    ->ArgNames({"scene", "baseline_cm", "outlier_pct"})
    ->Args({kBox, 50, 0})
    ->Args({kBox, 80, 0})
    ->Args({kBox, 50, 20})
    ->Args({kBox, 20, 0})
    ->Args({kBox, 5, 0})
    ->Args({kPlane, 60, 0})
    ->Args({kPlane, 60, 20})
    ->Args({kRotation, 0, 0})
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace pkslam
