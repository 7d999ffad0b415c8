#include "loopclosing/place_verifier.h"

#include <set>

#include "core/util/error.h"
#include "estimators/optim/sim3_optimization.h"
#include "map_model/estimation/ransac_inputs.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"

namespace pkslam {

void PlaceVerifierOptions::Check() const {
  PKSLAM_CHECK_OPTION(window_covisibles >= 0, "LoopClosing.window_covisibles", "{}",
                      window_covisibles);
  PKSLAM_CHECK_OPTION(bow_ratio > 0 && bow_ratio <= 1, "LoopClosing.bow_ratio", "{}", bow_ratio);
  PKSLAM_CHECK_OPTION(min_bow_matches >= 3 && min_ransac_inliers >= 3,
                      "LoopClosing.min_bow_matches", "{} / {}", min_bow_matches,
                      min_ransac_inliers);
  PKSLAM_CHECK_OPTION(ransac_iterations > 0, "LoopClosing.ransac_iterations", "{}",
                      ransac_iterations);
  PKSLAM_CHECK_OPTION(projection_radius > 0 && refined_radius > 0, "LoopClosing.radius", "{} / {}",
                      projection_radius, refined_radius);
  PKSLAM_CHECK_OPTION(projection_hamming > 0 && refined_hamming > 0, "LoopClosing.hamming",
                      "{} / {}", projection_hamming, refined_hamming);
  PKSLAM_CHECK_OPTION(min_projection_matches > 0 && min_optimised_inliers > 0 &&
                          min_refined_matches > 0 && min_confirmation_matches > 0,
                      "LoopClosing.min_matches", "{} / {} / {} / {}", min_projection_matches,
                      min_optimised_inliers, min_refined_matches, min_confirmation_matches);
}

namespace {

std::vector<KeyFramePtr> WindowOf(KeyFrame* kf, int covisibles) {
  std::vector<KeyFramePtr> window;
  Map* map = kf->map();
  if (map == nullptr) return window;
  if (KeyFramePtr self = map->Share(kf)) window.push_back(self);
  for (KeyFrame* c : kf->BestCovisibles(covisibles)) {
    if (c->IsBad()) continue;
    if (KeyFramePtr p = map->Share(c)) window.push_back(p);
  }
  return window;
}

std::vector<MapPointPtr> PointsOf(const std::vector<KeyFramePtr>& window) {
  std::map<MapPointId, MapPointPtr> points;
  for (const auto& kf : window) {
    for (const auto& mp : kf->map_points()) {
      if (mp && !mp->IsBad()) points.emplace(mp->id(), mp);
    }
  }
  std::vector<MapPointPtr> out;
  out.reserve(points.size());
  for (auto& [id, mp] : points) out.push_back(std::move(mp));
  return out;
}

int CountNonNull(const std::vector<MapPointPtr>& v) {
  int n = 0;
  for (const auto& p : v) n += p ? 1 : 0;
  return n;
}

// Pairs for the Sim3 optimisation from per-keypoint matches of kf1 to points of kf2's window.
// A window point kf2 does not observe gets its own projection in kf2 as the second
// observation (ORB-SLAM3's "all points" variant), so it constrains the model in 3-D.
std::vector<Sim3Match> PairsForOptimisation(const KeyFrame& kf1, const KeyFrame& kf2,
                                            const std::vector<MapPointPtr>& matched) {
  const auto& sigma2 = kf1.rig().pyramid.sigma2;
  const PinholeIntrinsics camera2 = IntrinsicsOf(kf2);
  std::vector<Sim3Match> out;
  for (int i1 = 0; i1 < kf1.size(); ++i1) {
    const MapPointPtr& mp2 = matched[static_cast<std::size_t>(i1)];
    const MapPointPtr& mp1 = kf1.map_point(i1);
    if (!mp1 || !mp2 || mp1->IsBad() || mp2->IsBad()) continue;
    Sim3Match m;
    m.point1 = kf1.camera_from_world() * mp1->position();
    m.point2 = kf2.camera_from_world() * mp2->position();
    if (m.point1.z() <= 0 || m.point2.z() <= 0) continue;
    const cv::KeyPoint& kp1 = kf1.keypoints_undistorted()[static_cast<std::size_t>(i1)];
    m.uv1 = Eigen::Vector2d(kp1.pt.x, kp1.pt.y);
    m.sigma2_1 = sigma2[static_cast<std::size_t>(kp1.octave)];
    m.index1 = i1;
    const int i2 = mp2->IndexInKeyFrame(&kf2);
    if (i2 >= 0) {
      const cv::KeyPoint& kp2 = kf2.keypoints_undistorted()[static_cast<std::size_t>(i2)];
      m.uv2 = Eigen::Vector2d(kp2.pt.x, kp2.pt.y);
      m.sigma2_2 = sigma2[static_cast<std::size_t>(kp2.octave)];
    } else {
      m.uv2 = camera2.Project<double>(m.point2);
      m.sigma2_2 = 1.0;
    }
    m.index2 = i2;
    out.push_back(m);
  }
  return out;
}

}  // namespace

std::optional<CommonRegion> VerifyCandidate(const KeyFramePtr& query, KeyFrame* candidate,
                                            const PlaceVerifierOptions& options,
                                            std::uint64_t seed) {
  if (query->IsBad() || candidate->IsBad() || candidate->map() == nullptr) return std::nullopt;
  const std::vector<KeyFramePtr> window = WindowOf(candidate, options.window_covisibles);
  if (window.empty()) return std::nullopt;

  // BoW: the window keyframe with the most matches carries the RANSAC.
  const OrbMatcher bow_matcher(options.bow_ratio, true);
  KeyFramePtr best;
  std::vector<MapPointPtr> best_matches;
  int best_count = 0;
  std::set<MapPointId> matched_anywhere;
  for (const auto& kf : window) {
    std::vector<MapPointPtr> m;
    const int n = bow_matcher.SearchByBoW(*query, *kf, &m);
    for (const auto& p : m) {
      if (p) matched_anywhere.insert(p->id());
    }
    if (n > best_count) {
      best_count = n;
      best = kf;
      best_matches = std::move(m);
    }
  }
  if (!best || static_cast<int>(matched_anywhere.size()) < options.min_bow_matches ||
      best_count < options.min_ransac_inliers) {
    return std::nullopt;
  }

  std::vector<Sim3Match> pairs = MakeSim3Matches(*query, *best, best_matches);
  if (static_cast<int>(pairs.size()) < options.min_ransac_inliers) return std::nullopt;
  Sim3SolverOptions ransac;
  ransac.fix_scale = options.fix_scale;
  ransac.min_inliers = options.min_ransac_inliers;
  ransac.max_iterations = options.ransac_iterations;
  ransac.seed = seed;
  Sim3Solver solver(std::move(pairs), IntrinsicsOf(*query), IntrinsicsOf(*best), ransac);
  Sim3RansacResult hypothesis;
  while (!hypothesis.found && !hypothesis.exhausted) hypothesis = solver.Iterate(20);
  if (!hypothesis.found) return std::nullopt;

  // Guided search of the whole window with the RANSAC model.
  CommonRegion region;
  region.query = query;
  region.matched = best;
  region.window = window;
  region.window_points = PointsOf(window);
  const OrbMatcher projection_matcher(0.9, true);
  Sim3d query_from_best = hypothesis.camera1_from_camera2;
  Sim3d query_camera_from_world = query_from_best * Sim3d(best->camera_from_world());
  std::vector<MapPointPtr> matched;
  const int n_projection = projection_matcher.SearchByProjection(
      *query, query_camera_from_world, region.window_points, &matched, options.projection_radius,
      options.projection_hamming);
  if (n_projection < options.min_projection_matches) return std::nullopt;

  Sim3OptimizationOptions optimisation;
  optimisation.fix_scale = options.fix_scale;
  const Sim3OptimizationResult refined =
      OptimizeSim3(PairsForOptimisation(*query, *best, matched), IntrinsicsOf(*query),
                   IntrinsicsOf(*best), query_from_best, optimisation);
  if (refined.num_inliers < options.min_optimised_inliers) return std::nullopt;

  query_from_best = refined.camera1_from_camera2;
  query_camera_from_world = query_from_best * Sim3d(best->camera_from_world());
  matched.clear();
  const int n_refined = projection_matcher.SearchByProjection(
      *query, query_camera_from_world, region.window_points, &matched, options.refined_radius,
      options.refined_hamming);
  if (n_refined < options.min_refined_matches) return std::nullopt;

  region.query_camera_from_world = query_camera_from_world;
  region.matched_points = std::move(matched);
  region.matches = CountNonNull(region.matched_points);
  return region;
}

int CountRegionMatches(const CommonRegion& region, const KeyFrame& keyframe,
                       const Sim3d& keyframe_camera_from_world, const PlaceVerifierOptions& options,
                       std::vector<MapPointPtr>* matched) {
  std::vector<MapPointPtr> local;
  std::vector<MapPointPtr>* out = matched != nullptr ? matched : &local;
  out->clear();
  const OrbMatcher matcher(0.9, true);
  return matcher.SearchByProjection(keyframe, keyframe_camera_from_world, region.window_points, out,
                                    options.refined_radius, options.refined_hamming);
}

Sim3d CarryOver(const CommonRegion& region, const KeyFrame& keyframe) {
  // S_kw' = T_kw * T_wq * S_qw': the odometry between the two keyframes is trusted.
  return Sim3d(keyframe.camera_from_world() * region.query->world_from_camera()) *
         region.query_camera_from_world;
}

int ConfirmByCovisibles(const CommonRegion& region, int n, const PlaceVerifierOptions& options) {
  int confirmed = 0;
  for (KeyFrame* kf : region.query->BestCovisibles(n)) {
    if (kf->IsBad()) continue;
    // A covisible of the query that is itself part of the window is no independent evidence.
    bool in_window = false;
    for (const auto& w : region.window) in_window = in_window || w.get() == kf;
    if (in_window) continue;
    const int matches = CountRegionMatches(region, *kf, CarryOver(region, *kf), options, nullptr);
    if (matches >= options.min_confirmation_matches) ++confirmed;
  }
  return confirmed;
}

}  // namespace pkslam
