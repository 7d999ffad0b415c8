#include "estimators/ransac/sim3_solver.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/util/error.h"

namespace pkslam {
namespace {

// Squared reprojection error of `p_camera` against `uv`; infinite behind the camera.
double SquaredError(const PinholeIntrinsics& camera, const Eigen::Vector3d& p_camera,
                    const Eigen::Vector2d& uv) {
  if (p_camera.z() <= 1e-9) return std::numeric_limits<double>::infinity();
  return (camera.Project(p_camera) - uv).squaredNorm();
}

}  // namespace

std::optional<Sim3d> AlignPoints(const std::vector<Eigen::Vector3d>& source,
                                 const std::vector<Eigen::Vector3d>& target, bool fix_scale) {
  PKSLAM_CHECK(source.size() == target.size(), "{} source vs {} target points", source.size(),
               target.size());
  const std::size_t n = source.size();
  if (n < 3) return std::nullopt;
  Eigen::Vector3d mean_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_t = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    mean_s += source[i];
    mean_t += target[i];
  }
  mean_s /= static_cast<double>(n);
  mean_t /= static_cast<double>(n);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();  // sum of (t - mean_t)(s - mean_s)^T
  double var_s = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d ds = source[i] - mean_s;
    cov += (target[i] - mean_t) * ds.transpose();
    var_s += ds.squaredNorm();
  }
  if (var_s <= 1e-18) return std::nullopt;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d& sv = svd.singularValues();
  // Collinear sources (or targets) leave the rotation about the line free.
  if (sv(1) <= 1e-9 * sv(0) || sv(0) <= 0) return std::nullopt;
  Eigen::Vector3d d(1, 1, 1);
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) d(2) = -1;
  const Eigen::Matrix3d r = svd.matrixU() * d.asDiagonal() * svd.matrixV().transpose();
  const double s = fix_scale ? 1.0 : sv.dot(d) / var_s;
  if (!(s > 0) || !std::isfinite(s)) return std::nullopt;
  return Sim3d(s, SO3d(r), mean_t - s * (r * mean_s));
}

void Sim3SolverOptions::Check() const {
  PKSLAM_CHECK_OPTION(probability > 0 && probability < 1, "probability", "{}", probability);
  PKSLAM_CHECK_OPTION(min_inliers >= 3, "min_inliers", "{}", min_inliers);
  PKSLAM_CHECK_OPTION(max_iterations >= 1, "max_iterations", "{}", max_iterations);
  PKSLAM_CHECK_OPTION(chi2 > 0, "chi2", "{}", chi2);
}

Sim3Solver::Sim3Solver(std::vector<Sim3Match> matches, const PinholeIntrinsics& camera1,
                       const PinholeIntrinsics& camera2, const Sim3SolverOptions& options)
    : matches_(std::move(matches)),
      camera1_(camera1),
      camera2_(camera2),
      options_(options),
      rng_(options.seed) {
  options_.Check();
  const auto n = static_cast<int>(matches_.size());
  if (n < options_.min_inliers) {
    budget_ = 0;
    return;
  }
  // Iterations for `probability` of drawing one all-inlier triple when just min_inliers of
  // the matches are inliers (ORB-SLAM's rule).
  const double epsilon = static_cast<double>(options_.min_inliers) / n;
  const double p_good = epsilon * epsilon * epsilon;
  int needed = options_.max_iterations;
  if (p_good >= 1.0) {
    needed = 1;
  } else {
    needed =
        static_cast<int>(std::ceil(std::log(1.0 - options_.probability) / std::log(1.0 - p_good)));
  }
  budget_ = std::max(1, std::min(needed, options_.max_iterations));
}

int Sim3Solver::CountInliers(const Sim3d& camera1_from_camera2, std::vector<bool>* inliers) const {
  const Sim3d camera2_from_camera1 = camera1_from_camera2.Inverse();
  inliers->assign(matches_.size(), false);
  int count = 0;
  for (std::size_t i = 0; i < matches_.size(); ++i) {
    const Sim3Match& m = matches_[i];
    const double e1 = SquaredError(camera1_, camera1_from_camera2 * m.point2, m.uv1);
    const double e2 = SquaredError(camera2_, camera2_from_camera1 * m.point1, m.uv2);
    if (e1 < options_.chi2 * m.sigma2_1 && e2 < options_.chi2 * m.sigma2_2) {
      (*inliers)[i] = true;
      ++count;
    }
  }
  return count;
}

Sim3RansacResult Sim3Solver::Iterate(int iterations) {
  Sim3RansacResult result;
  const std::size_t n = matches_.size();
  std::vector<std::size_t> pool(n);
  std::vector<bool> inliers;
  std::vector<Eigen::Vector3d> source(3), target(3);
  for (int it = 0; it < iterations && iterations_done_ < budget_; ++it) {
    ++iterations_done_;
    // Three distinct matches: a partial Fisher-Yates shuffle of the index pool.
    std::iota(pool.begin(), pool.end(), std::size_t{0});
    for (std::size_t k = 0; k < 3; ++k) {
      std::uniform_int_distribution<std::size_t> pick(k, n - 1);
      std::swap(pool[k], pool[pick(rng_)]);
      source[k] = matches_[pool[k]].point2;
      target[k] = matches_[pool[k]].point1;
    }
    const auto model = AlignPoints(source, target, options_.fix_scale);
    if (!model) continue;
    const int count = CountInliers(*model, &inliers);
    if (count >= best_inliers_) {
      best_inliers_ = count;
      best_ = *model;
    }
    if (count < options_.min_inliers) continue;

    Sim3d accepted = *model;
    int accepted_count = count;
    if (options_.refine) {
      // Two rounds of re-estimation from the inlier set.
      std::vector<bool> current = inliers;
      for (int round = 0; round < 2; ++round) {
        std::vector<Eigen::Vector3d> all_source, all_target;
        for (std::size_t i = 0; i < n; ++i) {
          if (!current[i]) continue;
          all_source.push_back(matches_[i].point2);
          all_target.push_back(matches_[i].point1);
        }
        const auto refined = AlignPoints(all_source, all_target, options_.fix_scale);
        if (!refined) break;
        std::vector<bool> refined_inliers;
        const int refined_count = CountInliers(*refined, &refined_inliers);
        if (refined_count < accepted_count) break;
        accepted = *refined;
        accepted_count = refined_count;
        current = refined_inliers;
      }
      inliers = std::move(current);
    }
    best_ = accepted;
    best_inliers_ = accepted_count;
    result.found = true;
    result.camera1_from_camera2 = accepted;
    result.inliers = std::move(inliers);
    result.num_inliers = accepted_count;
    break;
  }
  result.exhausted = iterations_done_ >= budget_;
  return result;
}

}  // namespace pkslam
