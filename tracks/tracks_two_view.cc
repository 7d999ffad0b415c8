#include "tracks/tracks_two_view.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/util/error.h"
#include "estimators/two_view/two_view_models.h"
#include "estimators/two_view/two_view_motion.h"
#include "estimators/two_view/two_view_refine.h"

namespace pkslam {

void TracksTwoViewOptions::Check() const {
  PKSLAM_CHECK_OPTION(sigma > 0, "sigma", "{}", sigma);
  PKSLAM_CHECK_OPTION(ransac_iterations > 0, "ransac iterations", "{}", ransac_iterations);
  PKSLAM_CHECK_OPTION(min_good_share > 0 && min_good_share <= 1, "min good share", "{}",
                      min_good_share);
  PKSLAM_CHECK_OPTION(max_ambiguity > 0 && max_ambiguity <= 1, "max ambiguity", "{}",
                      max_ambiguity);
  PKSLAM_CHECK_OPTION(min_points >= 8, "min init points", "{}", min_points);
  PKSLAM_CHECK_OPTION(min_parallax_deg >= 0 && min_parallax_deg < 90, "min init parallax", "{}",
                      min_parallax_deg);
}

namespace {

// Ray angle (degrees) at a point between two camera centres.
double ParallaxDeg(const Eigen::Vector3d& p, const Eigen::Vector3d& centre1,
                   const Eigen::Vector3d& centre2) {
  const Eigen::Vector3d a = (p - centre1).normalized();
  const Eigen::Vector3d b = (p - centre2).normalized();
  return std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

}  // namespace

TracksTwoViewResult ReconstructTwoViewTracks(const std::vector<IndexedObservation>& first,
                                             const std::vector<IndexedObservation>& second,
                                             const PinholeIntrinsics& camera,
                                             const TracksTwoViewOptions& options) {
  options.Check();
  TracksTwoViewResult r;
  two_view::Correspondences pixels;
  for (const IndexedObservation& o : first) {
    if (const IndexedObservation* o2 = FindObservation(second, o.track)) {
      r.tracks.push_back(o.track);
      pixels.first.push_back(o.uv);
      pixels.second.push_back(o2->uv);
    }
  }
  const int n = pixels.size();
  if (n < options.min_points) {
    r.failure = fmt::format("{} common tracks (at least {} needed)", n, options.min_points);
    return r;
  }
  // 1-2. Fundamental matrix by RANSAC (eight-point on Hartley-normalised points, scored by
  // the epipolar distance in both images; LO-RANSAC re-fits on the inliers).
  const auto sets = two_view::DrawMinimalSets(n, options.ransac_iterations, options.seed);
  two_view::RansacOptions ransac;
  ransac.sigma = options.sigma;
  ransac.refine_iterations = 10;
  ransac.reject_degenerate_samples = true;
  const two_view::ModelFit fit =
      two_view::RansacFundamental(pixels, two_view::NormalizePoints(pixels.first),
                                  two_view::NormalizePoints(pixels.second), sets, ransac);
  r.num_inliers = fit.num_inliers;
  if (fit.score <= 0 || fit.num_inliers < options.min_points) {
    r.failure = fmt::format("no fundamental matrix with {} inliers ({} found)", options.min_points,
                            fit.num_inliers);
    return r;
  }
  // 3-4. E = K^T F K and its four motions.
  const two_view::Pinhole pinhole{camera.fx, camera.fy, camera.cx, camera.cy};
  const Eigen::Matrix3d e21 = pinhole.K().transpose() * fit.matrix * pinhole.K();
  const std::vector<two_view::Motion> motions = two_view::DecomposeEssential(e21);
  two_view::Correspondences normalized;
  for (int k = 0; k < n; ++k) {
    normalized.first.push_back(pinhole.Normalize(pixels.first[static_cast<std::size_t>(k)]));
    normalized.second.push_back(pinhole.Normalize(pixels.second[static_cast<std::size_t>(k)]));
  }
  // 5. Cheirality: triangulate every inlier under each candidate; the right one puts (almost)
  // all of them in front of both cameras within the reprojection gate.
  // 99% gate (2 DoF): a 2-sigma gate would drop ~25% of correct points at the noise level.
  const double gate2 = two_view::kChi2TwoDof99 * options.sigma * options.sigma;
  std::vector<two_view::MotionCheck> checks;
  for (std::size_t c = 0; c < motions.size(); ++c) {
    checks.push_back(two_view::CheckMotion(motions[c], pixels, normalized, fit.inliers, pinhole,
                                           pinhole, gate2));
    r.candidate_good[c] = checks.back().num_good;
    if (r.best_candidate < 0 || checks.back().num_good > checks[r.best_candidate].num_good) {
      r.best_candidate = static_cast<int>(c);
    }
  }
  const two_view::MotionCheck& best = checks[static_cast<std::size_t>(r.best_candidate)];
  for (std::size_t c = 0; options.strict && c < checks.size(); ++c) {
    if (static_cast<int>(c) != r.best_candidate &&
        checks[c].num_good > options.max_ambiguity * best.num_good) {
      r.failure = fmt::format("ambiguous: candidates {} and {} triangulate {} and {} points",
                              r.best_candidate, c, best.num_good, checks[c].num_good);
      return r;
    }
  }
  if ((options.strict && best.num_good < options.min_good_share * fit.num_inliers) ||
      best.num_good < options.min_points) {
    r.failure = fmt::format("only {} of {} inliers triangulate in front of both cameras",
                            best.num_good, fit.num_inliers);
    return r;
  }
  // 6-7. The motion, refined on the triangulated points with the known K (the eight-point F
  // ignores it: Levenberg-Marquardt on the Sampson error, two_view_refine.h), and the linearly
  // triangulated map. Good points with any parallax count here: the small-baseline case is
  // judged by the median parallax below, as the thesis's fix does.
  two_view::Motion m = motions[static_cast<std::size_t>(r.best_candidate)];
  const two_view::MotionRefinement refined =
      two_view::RefineMotion(m, normalized, best.triangulated);
  two_view::MotionCheck check = best;
  {
    two_view::MotionCheck refined_check = two_view::CheckMotion(
        refined.motion, pixels, normalized, fit.inliers, pinhole, pinhole, gate2);
    if (refined_check.num_good >= best.num_good) {
      m = refined.motion;
      check = std::move(refined_check);
    }
  }
  r.camera2_from_camera1 = SE3d(SO3d::FitToMatrix(m.rotation), m.translation);
  const Eigen::Vector3d centre2 = -(m.rotation.transpose() * m.translation);
  std::vector<double> parallax;
  r.points_camera1.resize(static_cast<std::size_t>(n));
  r.triangulated.assign(static_cast<std::size_t>(n), false);
  for (int k = 0; k < n; ++k) {
    const std::size_t i = static_cast<std::size_t>(k);
    const Eigen::Vector3d& p = check.points[i];
    // CheckMotion's "good" includes far points of any depth sign; keep those in front.
    const bool good = fit.inliers[i] != 0 && p.allFinite() && p.z() > 0 &&
                      (m.rotation * p + m.translation).z() > 0;
    if (!good) continue;
    const double err1 = (pinhole.Project(p) - pixels.first[i]).squaredNorm();
    const double err2 =
        (pinhole.Project(m.rotation * p + m.translation) - pixels.second[i]).squaredNorm();
    if (err1 > gate2 || err2 > gate2) continue;
    r.points_camera1[i] = p;
    r.triangulated[i] = true;
    parallax.push_back(ParallaxDeg(p, Eigen::Vector3d::Zero(), centre2));
  }
  r.num_triangulated = static_cast<int>(parallax.size());
  if (r.num_triangulated < options.min_points) {
    r.failure = fmt::format("only {} points triangulated", r.num_triangulated);
    return r;
  }
  std::nth_element(parallax.begin(), parallax.begin() + static_cast<long>(parallax.size() / 2),
                   parallax.end());
  r.median_parallax_deg = parallax[parallax.size() / 2];
  if (r.median_parallax_deg < options.min_parallax_deg) {
    r.failure = fmt::format("median parallax {:.2f} deg < {:.2f}", r.median_parallax_deg,
                            options.min_parallax_deg);
    return r;
  }
  r.ok = true;
  return r;
}

}  // namespace pkslam
