// The calibration bundle adjustment's covariance: the sigmas a run reports.
#include <algorithm>
#include <cmath>
#include <optional>

#include "estimators/calibration/calibration_solve_state.h"
#include "estimators/optim/marginal_covariance.h"

namespace pkslam::calibration_solve {

// Before the covariance (the solve is done), the points whose directions the covariance's rank
// check would take for null ones, so that it refuses the whole covariance (every machine-hall
// replay did when the covariance came from Ceres' sparse QR):
// - a point the outlier pass left with three residuals or fewer (`rows_left`) tells nothing
//   about the other parameters (its own three coordinates absorb them), and with fewer than
//   three it has no position at all; it leaves the problem with its residuals, which keeps the
//   calibration's marginal covariance as it is;
// - a far point seen without stereo from nearby keyframes has almost no depth, numerically a
//   null direction (the rank tolerance is relative to the largest direction); a 100 m
//   prior on every point's position removes those and tells nothing worth the name about
//   anything else.
void RemoveNuisanceNullDirections(const std::vector<int>& rows_left,
                                  const std::vector<std::uint8_t>& point_added,
                                  ceres::Problem* ceres_problem, State* s) {
  constexpr double kPointPriorSigmaM = 100.0;
  for (std::size_t p = 0; p < rows_left.size(); ++p) {
    if (!point_added[p]) continue;
    double* point = s->point(static_cast<int>(p));
    if (rows_left[p] <= 3) {
      ceres_problem->RemoveParameterBlock(point);
      continue;
    }
    ceres_problem->AddResidualBlock(
        new EuclideanPriorError(Eigen::Map<const Eigen::Vector3d>(point),
                                Eigen::Vector3d::Constant(kPointPriorSigmaM)),
        nullptr, point);
  }
}

// The marginal covariance of the free calibration blocks (tangent space), written into the
// parameters' sigmas and, as the joint covariance of the reported scalars, into
// `parameter_covariance`. False when Ceres cannot compute it (rank-deficient Jacobian).
// `imu_expansion`, `stereo_expansion`: the extrinsic blocks' free tangent axes
// (SE3LeftSubsetManifold::Expansion).
bool FillSigmas(ceres::Problem* ceres_problem, State* s, const CalibrationBundleProblem& problem,
                int num_threads, const Eigen::MatrixXd& imu_expansion,
                const Eigen::MatrixXd& stereo_expansion,
                std::vector<CalibrationParameter>* parameters,
                Eigen::MatrixXd* parameter_covariance) {
  parameter_covariance->resize(0, 0);
  // A block's tangent covariance C maps to the reported scalars as J C J^T (report-ordered J).
  struct Entry {
    double* block;
    int first;             // index of its first scalar in `parameters`
    Eigen::MatrixXd j;     // reported scalars x block tangent (units included)
    bool ambient = false;  // intrinsics: ambient covariance (frozen coordinates: 0)
  };
  std::vector<Entry> entries;
  int index = 0;
  for (int c = 0; c < static_cast<int>(problem.initial.cameras.size()) && c < 2; ++c) {
    if (problem.free.intrinsics[c]) {
      entries.push_back({s->intrinsics(c), index,
                         Eigen::MatrixXd::Identity(kCalibIntrinsicsSize, kCalibIntrinsicsSize),
                         true});
    }
    index += kCalibIntrinsicsSize;
  }
  // The block B = X^-1 of the reported X = parent_from_child moves as Exp(e) B, so X moves as
  // X Exp(-e): rotation vector -R_X phi, translation -R_X rho (first order).
  const auto extrinsic_j = [](const SE3d& parent_from_child) {
    Eigen::MatrixXd j = Eigen::MatrixXd::Zero(6, 6);
    const Eigen::Matrix3d r = parent_from_child.RotationMatrix();
    j.block<3, 3>(0, 3) = -r * kRadToDeg;
    j.block<3, 3>(3, 0) = -r * 1e3;
    return j;
  };
  if (problem.initial.stereo()) {
    if (problem.free.stereo_extrinsic) {
      entries.push_back(
          {s->cam1_from_cam0(), index,
           extrinsic_j(PoseFromBlock(s->cam1_from_cam0()).Inverse()) * stereo_expansion});
    }
    index += 6;
  }
  if (problem.inertial) {
    if (problem.free.imu_rotation || problem.free.imu_translation) {
      entries.push_back(
          {s->cam0_from_body(), index,
           extrinsic_j(PoseFromBlock(s->cam0_from_body()).Inverse()) * imu_expansion});
    }
    index += 6;
    if (problem.free.time_offset) {
      entries.push_back({s->offset(), index, Eigen::MatrixXd::Constant(1, 1, 1e3)});
    }
    index += 1;
    if (problem.free.gyro_scale) {
      entries.push_back({s->gyro_scale(), index, Eigen::MatrixXd::Identity(3, 3) * 100.0});
    }
    index += 3;
    if (problem.free.accel_axes) {
      // Row-major: the diagonal in %, the misalignment in deg (CalibrationParameters).
      Eigen::MatrixXd j = Eigen::MatrixXd::Zero(9, 9);
      for (int i = 0; i < 9; ++i) j(i, i) = i % 4 == 0 ? 100.0 : kRadToDeg;
      entries.push_back({s->accel_axes(), index, j, /*ambient=*/!problem.free.accel_scale});
    }
  }
  if (entries.empty()) return true;
  std::vector<const double*> blocks;
  for (const Entry& e : entries) blocks.push_back(e.block);
  MarginalCovarianceOptions options;
  options.num_threads = num_threads;
  const std::optional<MarginalCovariance> covariance =
      ComputeMarginalCovariance(ceres_problem, blocks, options);
  if (!covariance) return false;
  // The joint covariance T C T^T, T block-diagonal: each entry's tangent -> reported map (its j,
  // through the manifold's plus Jacobian for ambient entries). The stereo rig's depth is a
  // combination of both cameras' intrinsics and the stereo rotation, whose errors offset each
  // other: its uncertainty needs the cross terms, which the sigmas leave out.
  const int n = static_cast<int>(parameters->size());
  Eigen::MatrixXd t = Eigen::MatrixXd::Zero(n, covariance->joint.rows());
  for (const Entry& e : entries) {
    const MarginalBlock& b = covariance->Find(e.block);
    const Eigen::MatrixXd map = e.ambient ? e.j * PlusJacobianOf(*ceres_problem, e.block) : e.j;
    t.block(e.first, b.offset, map.rows(), b.size) = map;
  }
  *parameter_covariance = t * covariance->joint * t.transpose();
  // The sigmas are its diagonal (a block's own J P C P^T J^T).
  for (int i = 0; i < n; ++i) {
    CalibrationParameter& p = (*parameters)[static_cast<std::size_t>(i)];
    if (p.free) {
      p.sigma = std::sqrt(std::max(0.0, (*parameter_covariance)(i, i)));
    } else {
      parameter_covariance->row(i).setZero();
      parameter_covariance->col(i).setZero();
    }
  }
  return true;
}

}  // namespace pkslam::calibration_solve
