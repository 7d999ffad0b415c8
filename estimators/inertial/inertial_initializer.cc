#include "estimators/inertial/inertial_initializer.h"

#include <ceres/ceres.h>

#include <cmath>
#include <memory>

#include "core/util/error.h"
#include "estimators/optim/ceres_setup.h"
#include "imu/imu_factors.h"
#include "imu/imu_manifolds.h"
#include "imu/preintegration.h"

namespace pkslam {
namespace {

void CheckInputs(const std::vector<InertialInitKeyFrame>& keyframes,
                 const std::vector<PreintegratedImu>& preintegrations, double time_tolerance) {
  PKSLAM_CHECK(keyframes.size() >= 2, "inertial initialisation needs >= 2 keyframes, got {}",
               keyframes.size());
  PKSLAM_CHECK(preintegrations.size() + 1 == keyframes.size(),
               "{} preintegrations for {} keyframes (need one per consecutive pair)",
               preintegrations.size(), keyframes.size());
  for (std::size_t k = 0; k + 1 < keyframes.size(); ++k) {
    const double gap = static_cast<double>(keyframes[k + 1].t_ns - keyframes[k].t_ns) * 1e-9;
    PKSLAM_CHECK(gap > 0, "keyframe times not increasing at index {}", k + 1);
    PKSLAM_CHECK(std::abs(gap - preintegrations[k].dt) <= time_tolerance,
                 "keyframes {} -> {} are {} s apart but their preintegration spans {} s", k, k + 1,
                 gap, preintegrations[k].dt);
  }
}

}  // namespace

void InertialInitializerOptions::Check() const {
  PKSLAM_CHECK_OPTION(gravity_magnitude > 0, "gravity_magnitude", "{}", gravity_magnitude);
  PKSLAM_CHECK_OPTION(gyro_bias_prior_information >= 0, "gyro_bias_prior_information", "{}",
                      gyro_bias_prior_information);
  PKSLAM_CHECK_OPTION(accel_bias_prior_information >= 0, "accel_bias_prior_information", "{}",
                      accel_bias_prior_information);
  PKSLAM_CHECK_OPTION(max_iterations > 0, "max_iterations", "{}", max_iterations);
  PKSLAM_CHECK_OPTION(min_scale > 0, "min_scale", "{}", min_scale);
  PKSLAM_CHECK_OPTION(time_tolerance >= 0, "time_tolerance", "{}", time_tolerance);
}

Eigen::Vector3d EstimateGravityDirection(const std::vector<InertialInitKeyFrame>& keyframes,
                                         const std::vector<PreintegratedImu>& preintegrations,
                                         const ImuBias& bias) {
  PKSLAM_CHECK(!preintegrations.empty() && preintegrations.size() + 1 == keyframes.size(),
               "{} preintegrations for {} keyframes", preintegrations.size(), keyframes.size());
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < preintegrations.size(); ++k) {
    sum -= keyframes[k].world_from_body.so3() * DeltaVelocity(preintegrations[k], bias);
  }
  PKSLAM_CHECK(sum.norm() > 0, "degenerate gravity direction (no velocity deltas)");
  return sum.normalized();
}

InertialInitResult InitializeInertial(const std::vector<InertialInitKeyFrame>& keyframes,
                                      const std::vector<PreintegratedImu>& preintegrations,
                                      const ImuBias& initial_bias,
                                      const InertialInitializerOptions& options) {
  options.Check();
  CheckInputs(keyframes, preintegrations, options.time_tolerance);
  const std::size_t n = keyframes.size();

  // Parameter blocks (initial values as ORB-SLAM3's InitializeIMU).
  std::vector<Eigen::Vector3d> velocities(n, Eigen::Vector3d::Zero());
  for (std::size_t k = 1; k < n; ++k) {
    const Eigen::Vector3d v = (keyframes[k].world_from_body.translation() -
                               keyframes[k - 1].world_from_body.translation()) /
                              preintegrations[k - 1].dt;
    velocities[k - 1] = v;
    velocities[k] = v;
  }
  Eigen::Vector3d bias_gyro = initial_bias.gyro;
  Eigen::Vector3d bias_accel = initial_bias.accel;
  double gravity_block[kGravityDirectionBlockSize];
  GravityRotationToBlock(GravityRotationFromDirection(
                             EstimateGravityDirection(keyframes, preintegrations, initial_bias)),
                         gravity_block);
  double log_scale = 0.0;

  // The problem borrows the cost functions and the manifold; they live until the solve ends.
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  GravityDirectionManifold gravity_manifold;
  ceres::Problem problem(ProblemOptions({.cost_functions = true}));
  for (std::size_t k = 0; k + 1 < n; ++k) {
    costs.push_back(std::make_unique<InertialGravityScaleError>(
        preintegrations[k], keyframes[k].world_from_body, keyframes[k + 1].world_from_body,
        options.gravity_magnitude));
    problem.AddResidualBlock(costs.back().get(), nullptr, velocities[k].data(),
                             velocities[k + 1].data(), bias_gyro.data(), bias_accel.data(),
                             gravity_block, &log_scale);
  }
  if (options.gyro_bias_prior_information > 0) {
    costs.push_back(std::make_unique<BiasPriorError>(Eigen::Vector3d::Zero(),
                                                     options.gyro_bias_prior_information));
    problem.AddResidualBlock(costs.back().get(), nullptr, bias_gyro.data());
  }
  if (options.accel_bias_prior_information > 0) {
    costs.push_back(std::make_unique<BiasPriorError>(Eigen::Vector3d::Zero(),
                                                     options.accel_bias_prior_information));
    problem.AddResidualBlock(costs.back().get(), nullptr, bias_accel.data());
  }
  problem.SetManifold(gravity_block, &gravity_manifold);
  if (!options.estimate_scale) problem.SetParameterBlockConstant(&log_scale);

  const ceres::Solver::Options solver_options =
      SolverOptions(ceres::DENSE_QR, options.max_iterations, /*num_threads=*/1);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);

  InertialInitResult result;
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.iterations = static_cast<int>(summary.iterations.size());
  result.world_from_gravity = GravityRotationFromBlock(gravity_block);
  result.gravity_world =
      result.world_from_gravity * Eigen::Vector3d(0, 0, -options.gravity_magnitude);
  result.scale = std::exp(log_scale);
  result.bias = ImuBias(bias_gyro, bias_accel);
  result.velocities_world = std::move(velocities);

  bool finite = std::isfinite(result.scale) && bias_gyro.allFinite() && bias_accel.allFinite();
  for (const Eigen::Vector3d& v : result.velocities_world) finite = finite && v.allFinite();
  if (!summary.IsSolutionUsable()) {
    result.message = "solver failed: " + summary.message;
  } else if (!finite) {
    result.message = "non-finite solution";
  } else if (result.scale < options.min_scale) {
    result.message = fmt::format("scale {} below {}", result.scale, options.min_scale);
  } else {
    result.success = true;
  }
  return result;
}

}  // namespace pkslam
