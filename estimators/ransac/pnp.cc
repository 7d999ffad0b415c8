#include "estimators/ransac/pnp.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <opengv/absolute_pose/CentralAbsoluteAdapter.hpp>
#include <opengv/absolute_pose/methods.hpp>
#include <opengv/sac/Ransac.hpp>
#include <opengv/sac_problems/absolute_pose/AbsolutePoseSacProblem.hpp>
#include <optional>

#include "core/util/error.h"

namespace pkslam {
namespace {

using opengv::absolute_pose::CentralAbsoluteAdapter;
using opengv::sac_problems::absolute_pose::AbsolutePoseSacProblem;

// OpenGV's transformation_t is world_from_camera [R | t].
SE3d CameraFromWorld(const opengv::transformation_t& world_from_camera) {
  const Eigen::Matrix3d r = world_from_camera.block<3, 3>(0, 0);
  return SE3d(SO3d::FitToMatrix(r), world_from_camera.col(3)).Inverse();
}

bool IsFinite(const opengv::transformation_t& t) { return t.allFinite(); }

void FillOpenGv(const std::vector<PnpCorrespondence>& correspondences,
                const PinholeIntrinsics& camera, opengv::bearingVectors_t* bearings,
                opengv::points_t* points) {
  bearings->clear();
  points->clear();
  for (const auto& c : correspondences) {
    bearings->push_back(camera.Bearing(c.uv));
    points->push_back(c.point_world);
  }
}

int CountPixelInliers(const std::vector<PnpCorrespondence>& correspondences,
                      const PinholeIntrinsics& camera, double chi2, const SE3d& camera_from_world,
                      std::vector<bool>* inliers) {
  inliers->assign(correspondences.size(), false);
  int count = 0;
  for (std::size_t i = 0; i < correspondences.size(); ++i) {
    const auto& c = correspondences[i];
    const Eigen::Vector3d p = camera_from_world * c.point_world;
    if (p.z() <= 1e-9) continue;
    if ((camera.Project(p) - c.uv).squaredNorm() < chi2 * c.sigma2) {
      (*inliers)[i] = true;
      ++count;
    }
  }
  return count;
}

std::vector<int> IndicesOf(const std::vector<bool>& mask) {
  std::vector<int> out;
  for (std::size_t i = 0; i < mask.size(); ++i) {
    if (mask[i]) out.push_back(static_cast<int>(i));
  }
  return out;
}

}  // namespace

// The adapter and the problem live in place, never on the heap on their own: libopengv's
// deleting destructors release through Eigen's aligned operator delete (free) while this
// C++17 translation unit allocates with the global operator new (Eigen drops its class
// operators when the compiler aligns by itself), an alloc-dealloc mismatch under ASan.
struct PnpRansac::OpenGv {
  opengv::bearingVectors_t bearings;
  opengv::points_t points;
  std::optional<CentralAbsoluteAdapter> adapter;  // the problem refers to it: declared first
  std::optional<AbsolutePoseSacProblem> problem;
};

void PnpRansacOptions::Check() const {
  PKSLAM_CHECK_OPTION(probability > 0 && probability < 1, "probability", "{}", probability);
  PKSLAM_CHECK_OPTION(min_inliers >= 4, "min_inliers", "{}", min_inliers);
  PKSLAM_CHECK_OPTION(min_inlier_ratio > 0 && min_inlier_ratio <= 1, "min_inlier_ratio", "{}",
                      min_inlier_ratio);
  PKSLAM_CHECK_OPTION(max_iterations >= 1, "max_iterations", "{}", max_iterations);
  PKSLAM_CHECK_OPTION(chi2 > 0, "chi2", "{}", chi2);
}

PnpRansac::PnpRansac(std::vector<PnpCorrespondence> correspondences,
                     const PinholeIntrinsics& camera, const PnpRansacOptions& options)
    : correspondences_(std::move(correspondences)),
      camera_(camera),
      options_(options),
      opengv_(std::make_unique<OpenGv>()),
      rng_(options.seed) {
  options_.Check();
  const auto n = static_cast<int>(correspondences_.size());
  required_inliers_ =
      std::max(options_.min_inliers, static_cast<int>(std::ceil(options_.min_inlier_ratio * n)));
  if (n < required_inliers_) return;  // budget 0: nothing to try
  FillOpenGv(correspondences_, camera_, &opengv_->bearings, &opengv_->points);
  opengv_->adapter.emplace(opengv_->bearings, opengv_->points);
  // randomSeed = false: OpenGV's own generator is never used here (we draw the samples).
  opengv_->problem.emplace(*opengv_->adapter, AbsolutePoseSacProblem::KNEIP, false);
  // Iterations to draw one all-inlier 4-sample with `probability` at the acceptance ratio.
  const double ratio = static_cast<double>(required_inliers_) / n;
  const double p_good = std::pow(ratio, 4);
  const int needed =
      p_good >= 1.0 ? 1
                    : static_cast<int>(
                          std::ceil(std::log(1.0 - options_.probability) / std::log(1.0 - p_good)));
  budget_ = std::max(1, std::min(needed, options_.max_iterations));
}

PnpRansac::~PnpRansac() = default;

int PnpRansac::CountInliers(const SE3d& camera_from_world, std::vector<bool>* inliers) const {
  return CountPixelInliers(correspondences_, camera_, options_.chi2, camera_from_world, inliers);
}

std::optional<SE3d> PnpRansac::Refine(const std::vector<bool>& inliers, int count,
                                      int* refined_count,
                                      std::vector<bool>* refined_inliers) const {
  const std::vector<int> indices = IndicesOf(inliers);
  if (indices.size() < 6) return std::nullopt;  // EPnP needs 6 points
  opengv::transformation_t world_from_camera =
      opengv::absolute_pose::epnp(*opengv_->adapter, indices);
  if (!IsFinite(world_from_camera)) return std::nullopt;
  opengv_->adapter->setR(world_from_camera.block<3, 3>(0, 0));
  opengv_->adapter->sett(world_from_camera.col(3));
  world_from_camera = opengv::absolute_pose::optimize_nonlinear(*opengv_->adapter, indices);
  if (!IsFinite(world_from_camera)) return std::nullopt;
  const SE3d pose = CameraFromWorld(world_from_camera);
  *refined_count = CountInliers(pose, refined_inliers);
  if (*refined_count < count) return std::nullopt;
  return pose;
}

PnpResult PnpRansac::Iterate(int iterations) {
  PnpResult result;
  const std::size_t n = correspondences_.size();
  std::vector<std::size_t> pool(n);
  std::vector<int> sample(4);
  std::vector<bool> inliers;
  for (int it = 0; it < iterations && iterations_done_ < budget_; ++it) {
    ++iterations_done_;
    std::iota(pool.begin(), pool.end(), std::size_t{0});
    for (std::size_t k = 0; k < 4; ++k) {
      std::uniform_int_distribution<std::size_t> pick(k, n - 1);
      std::swap(pool[k], pool[pick(rng_)]);
      sample[k] = static_cast<int>(pool[k]);
    }
    opengv::transformation_t world_from_camera;
    if (!opengv_->problem->computeModelCoefficients(sample, world_from_camera) ||
        !IsFinite(world_from_camera)) {
      continue;
    }
    SE3d pose = CameraFromWorld(world_from_camera);
    int count = CountInliers(pose, &inliers);
    if (count < required_inliers_) continue;
    if (options_.refine) {
      int refined_count = 0;
      std::vector<bool> refined_inliers;
      const auto refined = Refine(inliers, count, &refined_count, &refined_inliers);
      if (refined) {
        pose = *refined;
        count = refined_count;
        inliers = std::move(refined_inliers);
      }
    }
    result.found = true;
    result.camera_from_world = pose;
    result.inliers = std::move(inliers);
    result.num_inliers = count;
    break;
  }
  result.exhausted = iterations_done_ >= budget_;
  return result;
}

double AngularThreshold(double pixels, double focal) {
  return 1.0 - std::cos(std::atan(pixels / focal));
}

PnpResult SolvePnpOpenGvRansac(const std::vector<PnpCorrespondence>& correspondences,
                               const PinholeIntrinsics& camera, double threshold_pixels,
                               const PnpRansacOptions& options) {
  options.Check();
  PnpResult result;
  result.exhausted = true;
  if (static_cast<int>(correspondences.size()) < options.min_inliers) return result;
  opengv::bearingVectors_t bearings;
  opengv::points_t points;
  FillOpenGv(correspondences, camera, &bearings, &points);
  CentralAbsoluteAdapter adapter(bearings, points);
  auto problem =
      std::make_shared<AbsolutePoseSacProblem>(adapter, AbsolutePoseSacProblem::KNEIP, false);
  // Re-seed: the problem samples through rng_gen_, a copy of rng_alg_ bound at construction.
  problem->rng_alg_.seed(static_cast<std::mt19937::result_type>(options.seed));
  problem->rng_gen_ =
      std::make_shared<std::function<int()>>(std::bind(*problem->rng_dist_, problem->rng_alg_));
  opengv::sac::Ransac<AbsolutePoseSacProblem> ransac;
  ransac.sac_model_ = problem;
  ransac.threshold_ = AngularThreshold(threshold_pixels, 0.5 * (camera.fx + camera.fy));
  ransac.max_iterations_ = options.max_iterations;
  ransac.probability_ = options.probability;
  if (!ransac.computeModel(0) || !IsFinite(ransac.model_coefficients_)) return result;
  opengv::transformation_t world_from_camera = ransac.model_coefficients_;
  if (ransac.inliers_.size() >= 4) {
    adapter.setR(world_from_camera.block<3, 3>(0, 0));
    adapter.sett(world_from_camera.col(3));
    const opengv::transformation_t refined =
        opengv::absolute_pose::optimize_nonlinear(adapter, ransac.inliers_);
    if (IsFinite(refined)) world_from_camera = refined;
  }
  result.camera_from_world = CameraFromWorld(world_from_camera);
  // Inliers under the same angular test OpenGV used.
  result.inliers.assign(correspondences.size(), false);
  const SE3d& pose = result.camera_from_world;
  for (std::size_t i = 0; i < correspondences.size(); ++i) {
    const Eigen::Vector3d p = pose * correspondences[i].point_world;
    const double cos_angle = p.normalized().dot(bearings[i]);
    if (1.0 - cos_angle < ransac.threshold_) {
      result.inliers[i] = true;
      ++result.num_inliers;
    }
  }
  result.found = result.num_inliers >= options.min_inliers;
  return result;
}

}  // namespace pkslam
