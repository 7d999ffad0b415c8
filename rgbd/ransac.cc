#include "rgbd/ransac.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "core/util/error.h"
#include "rgbd/rigid_alignment.h"

namespace pkslam::rgbd {

void RansacOptions::Check() const {
  PKSLAM_CHECK_OPTION(inlier_threshold_m > 0, "ransac.inlier_threshold_m", "{}",
                      inlier_threshold_m);
  PKSLAM_CHECK_OPTION(confidence > 0 && confidence < 1, "ransac.confidence", "{}", confidence);
  PKSLAM_CHECK_OPTION(max_iterations >= 1, "ransac.max_iterations", "{}", max_iterations);
  PKSLAM_CHECK_OPTION(min_inliers >= 3, "ransac.min_inliers", "{}", min_inliers);
}

int RansacIterationCount(double confidence, double inlier_ratio, int sample_size,
                         int max_iterations) {
  PKSLAM_CHECK(confidence > 0 && confidence < 1 && sample_size >= 1 && max_iterations >= 1,
               "p {} k {} max {}", confidence, sample_size, max_iterations);
  if (inlier_ratio >= 1) return 1;
  if (inlier_ratio <= 0) return max_iterations;
  const double all_good = std::pow(inlier_ratio, sample_size);  // w^k
  const double denominator = std::log1p(-all_good);             // log(1 - w^k)
  if (denominator >= 0) return max_iterations;                  // w^k below double precision
  const double n = std::ceil(std::log1p(-confidence) / denominator);
  if (!(n < max_iterations)) return max_iterations;
  return std::max(1, static_cast<int>(n));
}

namespace {

// Indices of pairs whose residual under `t` is below the threshold.
void CollectInliers(std::span<const Eigen::Vector3d> source,
                    std::span<const Eigen::Vector3d> target, const SE3d& t, double threshold,
                    std::vector<int>* inliers) {
  inliers->clear();
  const double threshold2 = threshold * threshold;
  const Eigen::Matrix3d r = t.RotationMatrix();
  for (std::size_t i = 0; i < source.size(); ++i) {
    if ((target[i] - (r * source[i] + t.translation())).squaredNorm() < threshold2) {
      inliers->push_back(static_cast<int>(i));
    }
  }
}

}  // namespace

RansacResult EstimateRigidRansac(std::span<const Eigen::Vector3d> source,
                                 std::span<const Eigen::Vector3d> target,
                                 const RansacOptions& options) {
  options.Check();
  PKSLAM_CHECK(source.size() == target.size(), "{} vs {}", source.size(), target.size());
  constexpr int kSampleSize = 3;
  RansacResult result;
  const int n = static_cast<int>(source.size());
  if (n < std::max(kSampleSize, options.min_inliers)) return result;

  std::mt19937_64 rng(options.seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  std::vector<int> best_inliers;
  std::vector<int> inliers;
  SE3d best;
  int needed = options.max_iterations;
  int iteration = 0;
  for (; iteration < needed; ++iteration) {
    int sample[kSampleSize];
    sample[0] = pick(rng);
    do sample[1] = pick(rng);
    while (sample[1] == sample[0]);
    do sample[2] = pick(rng);
    while (sample[2] == sample[0] || sample[2] == sample[1]);
    const auto model = AlignRigid(source, target, std::span<const int>(sample, kSampleSize));
    if (!model) continue;  // collinear sample
    CollectInliers(source, target, *model, options.inlier_threshold_m, &inliers);
    if (inliers.size() > best_inliers.size()) {
      best_inliers.swap(inliers);
      best = *model;
      const double w = static_cast<double>(best_inliers.size()) / n;
      needed = RansacIterationCount(options.confidence, w, kSampleSize, options.max_iterations);
    }
  }
  result.iterations = iteration;
  if (static_cast<int>(best_inliers.size()) < kSampleSize) return result;

  // Refit on the consensus set, then take the consensus of the refit (twice: the set can
  // grow once the model is no longer biased by the minimal sample).
  for (int round = 0; round < 2; ++round) {
    const auto refit = AlignRigid(source, target, best_inliers);
    if (!refit) break;
    CollectInliers(source, target, *refit, options.inlier_threshold_m, &inliers);
    if (inliers.size() < best_inliers.size()) break;
    best = *refit;
    best_inliers.swap(inliers);
  }
  if (static_cast<int>(best_inliers.size()) < options.min_inliers) return result;
  result.success = true;
  result.target_from_source = best;
  result.inliers = std::move(best_inliers);
  return result;
}

}  // namespace pkslam::rgbd
