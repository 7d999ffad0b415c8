// Costs of the inertial hot paths: preintegrating one 20 Hz frame interval of 200 Hz samples,
// and evaluating the inertial edge with all its Jacobians.
#include <benchmark/benchmark.h>

#include <vector>

#include "imu/imu_factors.h"
#include "imu/imu_manifolds.h"
#include "imu/imu_test_utils.h"
#include "imu/preintegration.h"

namespace pkslam {
namespace {

using testing::HelixMotion;
using testing::kTestGravity;
using testing::SampleImu;

void BM_PreintegrateFrameInterval(benchmark::State& state) {
  const auto scheme = static_cast<ImuIntegrationScheme>(state.range(0));
  const std::vector<ImuMeasurement> samples =
      SampleImu(HelixMotion(), 0, 60'000'000, 5'000'000, {}, {}, nullptr);
  for (auto _ : state) {
    PreintegratedImu pim = StartPreintegration({}, ImuNoise{}, scheme);
    IntegrateSamples(samples, 2'000'000, 52'000'000, &pim);
    benchmark::DoNotOptimize(pim.covariance.data());
  }
}
BENCHMARK(BM_PreintegrateFrameInterval)
    ->Arg(static_cast<int>(ImuIntegrationScheme::kMidpoint))
    ->Arg(static_cast<int>(ImuIntegrationScheme::kOrbSlam3));

void BM_InertialErrorWithJacobians(benchmark::State& state) {
  const HelixMotion motion;
  PreintegratedImu pim = StartPreintegration({}, ImuNoise{});
  IntegrateSamples(SampleImu(motion, 0, 300'000'000, 5'000'000, {}, {}, nullptr), 0, 250'000'000,
                   &pim);
  const InertialError cost(pim, kTestGravity);
  const NavState a = motion.State(0.0), b = motion.State(0.25);
  double pose_i[7], pose_j[7], v_i[3] = {0.1, 1.6, 0.7}, v_j[3] = {-0.3, 1.5, 0.6};
  double bg[3] = {0.01, 0, 0}, ba[3] = {0, 0.1, 0};
  BodyPoseToBlock(a.world_from_body, pose_i);
  BodyPoseToBlock(b.world_from_body, pose_j);
  const double* params[] = {pose_i, v_i, bg, ba, pose_j, v_j};
  double residuals[9], j0[63], j1[27], j2[27], j3[27], j4[63], j5[27];
  double* jacobians[] = {j0, j1, j2, j3, j4, j5};
  for (auto _ : state) {
    cost.Evaluate(params, residuals, jacobians);
    benchmark::DoNotOptimize(residuals);
    benchmark::DoNotOptimize(j4);
  }
}
BENCHMARK(BM_InertialErrorWithJacobians);

}  // namespace
}  // namespace pkslam
