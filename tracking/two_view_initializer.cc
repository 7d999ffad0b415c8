#include "tracking/two_view_initializer.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <numeric>
#include <random>

#include "core/util/error.h"
#include "estimators/two_view/two_view_models.h"
#include "estimators/two_view/two_view_motion.h"
#include "estimators/two_view/two_view_refine.h"

namespace pkslam {

using two_view::Correspondences;
using two_view::MinimalSet;
using two_view::ModelFit;
using two_view::Motion;
using two_view::MotionCheck;
using two_view::Pinhole;

void TwoViewOptions::Check() const {
  PKSLAM_CHECK_OPTION(sigma > 0, "two_view.sigma", "{}", sigma);
  PKSLAM_CHECK_OPTION(iterations >= 1, "two_view.iterations", "{}", iterations);
  PKSLAM_CHECK_OPTION(min_parallax_deg >= 0 && min_parallax_deg < 90, "two_view.min_parallax_deg",
                      "{}", min_parallax_deg);
  PKSLAM_CHECK_OPTION(min_triangulated >= 1, "two_view.min_triangulated", "{}", min_triangulated);
  PKSLAM_CHECK_OPTION(refine_iterations >= 0, "two_view.refine_iterations", "{}",
                      refine_iterations);
  PKSLAM_CHECK_OPTION(degenerate_f_share > 0, "two_view.degenerate_f_share", "{}",
                      degenerate_f_share);
  PKSLAM_CHECK_OPTION(min_homography_ratio > 0 && min_homography_ratio < 1,
                      "two_view.min_homography_ratio", "{}", min_homography_ratio);
}

const char* ToString(TwoViewRejection rejection) {
  switch (rejection) {
    case TwoViewRejection::kNone:
      return "none";
    case TwoViewRejection::kTooFewMatches:
      return "too few matches";
    case TwoViewRejection::kNoModel:
      return "no model";
    case TwoViewRejection::kDegenerateModel:
      return "degenerate homography";
    case TwoViewRejection::kAmbiguous:
      return "ambiguous motion hypotheses";
    case TwoViewRejection::kTooFewGood:
      return "too few triangulated points";
    case TwoViewRejection::kLowParallax:
      return "low parallax";
  }
  return "?";
}

namespace {

// ORB-SLAM's acceptance constants (TwoViewReconstruction): the winner must triangulate this
// share of the model's inliers; F: no other hypothesis may reach kSimilarShareF of the best's
// good count; H: the runner-up must stay below kSecondShareH of it.
constexpr double kMinGoodShareOfInliers = 0.9;
constexpr double kSimilarShareF = 0.7;
constexpr double kSecondShareH = 0.75;
// Reprojection gate of triangulated points: error^2 < 4 sigma^2 in both images.
constexpr double kReprojectionGateSigmas2 = 4.0;

Pinhole PinholeOf(const Frame& frame) {
  const CameraRig& rig = frame.rig();
  return Pinhole{rig.fx, rig.fy, rig.cx, rig.cy};
}

struct Hypotheses {
  std::vector<Motion> motions;
  std::vector<MotionCheck> checks;
  int best = -1;
};

Hypotheses CheckAll(std::vector<Motion> motions, const Correspondences& pixels,
                    const Correspondences& normalized, const ModelFit& model,
                    const Pinhole& camera1, const Pinhole& camera2, double sigma,
                    TwoViewReport* report) {
  Hypotheses h;
  h.motions = std::move(motions);
  const double gate2 = kReprojectionGateSigmas2 * sigma * sigma;
  for (const Motion& m : h.motions) {
    h.checks.push_back(
        two_view::CheckMotion(m, pixels, normalized, model.inliers, camera1, camera2, gate2));
    const MotionCheck& c = h.checks.back();
    report->hypothesis_good.push_back(c.num_good);
    report->hypothesis_parallax.push_back(c.parallax_deg);
    // First best on ties (deterministic).
    if (h.best < 0 || c.num_good > h.checks[h.best].num_good) {
      h.best = static_cast<int>(h.checks.size()) - 1;
    }
  }
  report->best_hypothesis = h.best;
  return h;
}

// ORB-SLAM's ReconstructF acceptance. Returns kNone when the best hypothesis is accepted.
TwoViewRejection AcceptFundamental(const Hypotheses& h, int num_inliers,
                                   const TwoViewOptions& options) {
  const int best_good = h.checks[h.best].num_good;
  int similar = 0;
  for (const MotionCheck& c : h.checks) {
    if (c.num_good > kSimilarShareF * best_good) ++similar;
  }
  const int min_good =
      std::max(static_cast<int>(kMinGoodShareOfInliers * num_inliers), options.min_triangulated);
  if (best_good < min_good) return TwoViewRejection::kTooFewGood;
  if (similar > 1) return TwoViewRejection::kAmbiguous;
  if (!(h.checks[h.best].parallax_deg > options.min_parallax_deg)) {
    return TwoViewRejection::kLowParallax;
  }
  return TwoViewRejection::kNone;
}

// ORB-SLAM's ReconstructH acceptance.
TwoViewRejection AcceptHomography(const Hypotheses& h, int num_inliers,
                                  const TwoViewOptions& options) {
  const int best_good = h.checks[h.best].num_good;
  int second_good = 0;
  for (int i = 0; i < static_cast<int>(h.checks.size()); ++i) {
    if (i != h.best) second_good = std::max(second_good, h.checks[i].num_good);
  }
  if (!(best_good > options.min_triangulated) ||
      !(best_good > kMinGoodShareOfInliers * num_inliers)) {
    return TwoViewRejection::kTooFewGood;
  }
  if (!(second_good < kSecondShareH * best_good)) return TwoViewRejection::kAmbiguous;
  if (!(h.checks[h.best].parallax_deg >= options.min_parallax_deg)) {
    return TwoViewRejection::kLowParallax;
  }
  return TwoViewRejection::kNone;
}

}  // namespace

std::optional<TwoViewResult> ReconstructTwoView(const Frame& first, const Frame& second,
                                                const std::vector<int>& matches12,
                                                const TwoViewOptions& options) {
  TwoViewReport report;
  return ReconstructTwoView(first, second, matches12, options, &report);
}

std::optional<TwoViewResult> ReconstructTwoView(const Frame& first, const Frame& second,
                                                const std::vector<int>& matches12,
                                                const TwoViewOptions& options,
                                                TwoViewReport* report) {
  options.Check();
  PKSLAM_CHECK(report != nullptr, "report must not be null");
  PKSLAM_CHECK(static_cast<int>(matches12.size()) == first.size(),
               "matches12 has {} entries for {} keypoints", matches12.size(), first.size());
  *report = TwoViewReport{};

  // Matched pairs (undistorted pixels) and the first-frame keypoint of each.
  const auto& kps1 = first.keypoints_undistorted();
  const auto& kps2 = second.keypoints_undistorted();
  Correspondences pixels;
  std::vector<int> keypoint1;
  for (int i1 = 0; i1 < first.size(); ++i1) {
    const int i2 = matches12[i1];
    if (i2 < 0) continue;
    PKSLAM_CHECK(i2 < second.size(), "match {} -> {} beyond {} keypoints", i1, i2, second.size());
    pixels.first.emplace_back(kps1[i1].pt.x, kps1[i1].pt.y);
    pixels.second.emplace_back(kps2[i2].pt.x, kps2[i2].pt.y);
    keypoint1.push_back(i1);
  }
  const int n = pixels.size();
  report->num_matches = n;
  if (n < std::max(two_view::kMinimalSetSize, options.min_triangulated)) {
    report->rejection = TwoViewRejection::kTooFewMatches;
    return std::nullopt;
  }

  // Both models on the same minimal sets, concurrently (each task only reads shared data).
  const std::vector<MinimalSet> sets =
      two_view::DrawMinimalSets(n, options.iterations, options.seed);
  const two_view::NormalizedPoints normalized1 = two_view::NormalizePoints(pixels.first);
  const two_view::NormalizedPoints normalized2 = two_view::NormalizePoints(pixels.second);
  two_view::RansacOptions ransac;
  ransac.sigma = options.sigma;
  ransac.refine_iterations = options.refine_iterations;
  ransac.reject_degenerate_samples = options.reject_degenerate_samples;
  const auto find_h = [&] {
    return two_view::RansacHomography(pixels, normalized1, normalized2, sets, ransac);
  };
  ModelFit fit_h, fit_f;
  if (options.parallel) {
    auto future_h = std::async(std::launch::async, find_h);
    fit_f = two_view::RansacFundamental(pixels, normalized1, normalized2, sets, ransac);
    fit_h = future_h.get();
  } else {
    fit_h = find_h();
    fit_f = two_view::RansacFundamental(pixels, normalized1, normalized2, sets, ransac);
  }
  report->score_homography = fit_h.score;
  report->score_fundamental = fit_f.score;
  if (!(fit_h.score + fit_f.score > 0)) {
    report->rejection = TwoViewRejection::kNoModel;
    return std::nullopt;
  }
  const double ratio_h = fit_h.score / (fit_h.score + fit_f.score);
  report->homography_ratio = ratio_h;
  report->homography_share =
      fit_h.score > 0
          ? two_view::HomographyShare(fit_h.matrix, pixels, fit_f.inliers, options.sigma)
          : 0.0;
  const bool use_h = ratio_h > options.min_homography_ratio ||
                     report->homography_share >= options.degenerate_f_share;
  report->used_homography = use_h;
  const ModelFit& model = use_h ? fit_h : fit_f;
  report->num_model_inliers = model.num_inliers;

  // Motion hypotheses of the chosen model.
  const Pinhole camera1 = PinholeOf(first);
  const Pinhole camera2 = PinholeOf(second);
  std::vector<Motion> motions;
  if (use_h) {
    const Eigen::Matrix3d a21 = camera2.K().inverse() * model.matrix * camera1.K();
    for (const auto& pm : two_view::DecomposeHomography(a21)) motions.push_back(pm.motion);
    if (motions.empty()) {
      report->rejection = TwoViewRejection::kDegenerateModel;
      return std::nullopt;
    }
  } else {
    const Eigen::Matrix3d e21 = camera2.K().transpose() * model.matrix * camera1.K();
    motions = two_view::DecomposeEssential(e21);
  }

  Correspondences normalized;
  normalized.first.reserve(n);
  normalized.second.reserve(n);
  for (int k = 0; k < n; ++k) {
    normalized.first.push_back(camera1.Normalize(pixels.first[k]));
    normalized.second.push_back(camera2.Normalize(pixels.second[k]));
  }
  const Hypotheses h = CheckAll(std::move(motions), pixels, normalized, model, camera1, camera2,
                                options.sigma, report);
  report->rejection = use_h ? AcceptHomography(h, model.num_inliers, options)
                            : AcceptFundamental(h, model.num_inliers, options);
  if (report->rejection != TwoViewRejection::kNone) return std::nullopt;

  Motion best = h.motions[h.best];
  MotionCheck check = h.checks[h.best];
  if (options.refine_motion) {
    // First on the points the accepted hypothesis triangulated; then on every correspondence
    // the refined motion explains within the 99% 1-DoF gate (the Sampson distance has about
    // the keypoint sigma): the per-image epipolar gates keep only ~84% of true matches at
    // that noise, and dropping the tails costs accuracy (sweep: median translation error
    // 0.58 -> 0.43 deg).
    const two_view::MotionRefinement first_pass =
        two_view::RefineMotion(best, normalized, check.triangulated);
    const double focal = std::sqrt(camera1.fx * camera1.fy);
    const double gate = std::sqrt(two_view::kChi2OneDof99) * options.sigma / focal;
    const two_view::MotionRefinement refined =
        two_view::RefineMotion(first_pass.motion, normalized,
                               two_view::SampsonInliers(first_pass.motion, normalized, gate));
    MotionCheck refined_check =
        two_view::CheckMotion(refined.motion, pixels, normalized, model.inliers, camera1, camera2,
                              kReprojectionGateSigmas2 * options.sigma * options.sigma);
    // Guard against a refinement that went astray (not seen in the sweeps): it must keep
    // the accepted hypothesis' support.
    if (refined_check.num_good >= kMinGoodShareOfInliers * check.num_good) {
      report->sampson_rms_before = first_pass.initial_rms;
      report->sampson_rms_after = refined.final_rms;
      best = refined.motion;
      check = std::move(refined_check);
    }
  }
  TwoViewResult result;
  result.camera2_from_camera1 = SE3d(best.rotation, best.translation);
  result.points.assign(first.size(), Eigen::Vector3d::Zero());
  result.triangulated.assign(first.size(), false);
  for (int k = 0; k < n; ++k) {
    if (!check.triangulated[k]) continue;
    result.points[keypoint1[k]] = check.points[k];
    result.triangulated[keypoint1[k]] = true;
    ++result.num_triangulated;
  }
  result.used_homography = use_h;
  result.parallax_deg = check.parallax_deg;
  return result;
}

}  // namespace pkslam
