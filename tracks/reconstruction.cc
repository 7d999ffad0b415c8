#include "tracks/reconstruction.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <set>
#include <utility>

#include "core/util/error.h"
#include "estimators/optim/bundle_adjustment.h"
#include "estimators/optim/pose_solve.h"
#include "estimators/ransac/pnp.h"
#include "estimators/two_view/two_view_motion.h"

namespace pkslam {

TracksKeyframeRule ParseTracksKeyframeRule(std::string_view name) {
  if (name == "ptam") return TracksKeyframeRule::kPtam;
  if (name == "match-count") return TracksKeyframeRule::kMatchCount;
  if (name == "interval") return TracksKeyframeRule::kInterval;
  if (name == "ratio") return TracksKeyframeRule::kRatio;
  throw OptionError(
      fmt::format("keyframe rule '{}' (expected ptam|match-count|interval|ratio)", name));
}

std::string_view TracksKeyframeRuleName(TracksKeyframeRule rule) {
  switch (rule) {
    case TracksKeyframeRule::kPtam:
      return "ptam";
    case TracksKeyframeRule::kMatchCount:
      return "match-count";
    case TracksKeyframeRule::kInterval:
      return "interval";
    case TracksKeyframeRule::kRatio:
      return "ratio";
  }
  return "?";
}

TracksInitMode ParseTracksInitMode(std::string_view name) {
  if (name == "auto") return TracksInitMode::kAuto;
  if (name == "first-two") return TracksInitMode::kFirstTwo;
  if (name == "fixed") return TracksInitMode::kFixed;
  throw OptionError(fmt::format("init mode '{}' (expected auto|first-two|fixed)", name));
}

std::string_view TracksInitModeName(TracksInitMode mode) {
  switch (mode) {
    case TracksInitMode::kAuto:
      return "auto";
    case TracksInitMode::kFirstTwo:
      return "first-two";
    case TracksInitMode::kFixed:
      return "fixed";
  }
  return "?";
}

void TracksReconstructionOptions::Check() const {
  baseline.Check();
  two_view.Check();
  PKSLAM_CHECK_OPTION(ratio_max > 0 && ratio_min_frames >= 1, "ratio rule", "{} / {}", ratio_max,
                      ratio_min_frames);
  PKSLAM_CHECK_OPTION(starving_share >= 0 && starving_share < 1, "starving share", "{}",
                      starving_share);
  PKSLAM_CHECK_OPTION(init_mode != TracksInitMode::kFixed || init_second_frame > 0, "init frame",
                      "{} (fixed initialisation needs a later frame)", init_second_frame);
  PKSLAM_CHECK_OPTION(init_search_frames >= 1, "init search", "{}", init_search_frames);
  PKSLAM_CHECK_OPTION(init_min_parallax_deg >= 0 && init_min_parallax_deg < 90, "init parallax",
                      "{}", init_min_parallax_deg);
  PKSLAM_CHECK_OPTION(min_triangulation_parallax_deg >= 0, "triangulation parallax", "{}",
                      min_triangulation_parallax_deg);
  PKSLAM_CHECK_OPTION(local_window >= 2, "local window", "{}", local_window);
  PKSLAM_CHECK_OPTION(min_tracked >= 6, "min tracked", "{}", min_tracked);
}

namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double RayAngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 /
         std::numbers::pi;
}

// The processor's state. Keyframe poses are the estimates bundle adjustment refines; other
// frames hold their pose relative to the keyframe that was latest when they were tracked, so
// they follow it (ORB-SLAM's convention for the full trajectory).
class Reconstructor {
 public:
  Reconstructor(const TrackSet& tracks, const TrackIndex& index,
                const TracksReconstructionOptions& options)
      : tracks_(tracks), index_(index), options_(options), camera_(tracks.camera) {
    const double sigma = options_.two_view.sigma;
    inv_sigma2_ = 1.0 / (sigma * sigma);
    out_.frames.resize(static_cast<std::size_t>(index.num_frames()));
    out_.points.resize(static_cast<std::size_t>(index.num_tracks()));
    reference_.assign(static_cast<std::size_t>(index.num_frames()), -1);
    relative_.resize(static_cast<std::size_t>(index.num_frames()));
    std::vector<double> steps;
    for (int k = 1; k < index.num_frames(); ++k) {
      const double dt = index.times_s[static_cast<std::size_t>(k)] -
                        index.times_s[static_cast<std::size_t>(k - 1)];
      if (std::isfinite(dt) && dt > 0) steps.push_back(dt);
    }
    if (!steps.empty()) {
      std::nth_element(steps.begin(), steps.begin() + static_cast<long>(steps.size() / 2),
                       steps.end());
      fps_ = 1.0 / steps[steps.size() / 2];
    }
    if (options_.keyframe_rule != TracksKeyframeRule::kRatio) {
      const BaselineKind kind =
          options_.keyframe_rule == TracksKeyframeRule::kPtam         ? BaselineKind::kPtam
          : options_.keyframe_rule == TracksKeyframeRule::kMatchCount ? BaselineKind::kMatchCount
                                                                      : BaselineKind::kInterval;
      selector_ = std::make_unique<BaselineSelector>(kind, options_.baseline);
    }
  }

  TracksReconstruction Run(const std::function<void(int, int)>& progress) {
    const Clock::time_point start = Clock::now();
    Initialise();
    out_.seconds_init = SecondsSince(start);
    const int n = index_.num_frames();
    // The frames between the initial pair, then every later one.
    for (int k = out_.init_first + 1; k < n; ++k) {
      if (k == out_.init_second) continue;
      ProcessFrame(k, /*may_be_keyframe=*/k > out_.init_second);
      if (progress && (k % 50 == 0 || k == n - 1)) progress(k + 1, n);
    }
    if (options_.global_ba) {
      const Clock::time_point t = Clock::now();
      std::vector<int> all(keyframes_.size());
      for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
      BundleAdjust(all);
      out_.seconds_mapping += SecondsSince(t);
    }
    const Clock::time_point t_finish = Clock::now();
    Finish();
    out_.seconds_tracking += SecondsSince(t_finish);
    out_.seconds_total = SecondsSince(start);
    return std::move(out_);
  }

 private:
  SE3d& KeyframePose(int kf) { return keyframe_poses_[static_cast<std::size_t>(kf)]; }

  SE3d CurrentPose(int frame) const {
    const int ref = reference_[static_cast<std::size_t>(frame)];
    return relative_[static_cast<std::size_t>(frame)] *
           keyframe_poses_[static_cast<std::size_t>(ref)];
  }

  const std::vector<IndexedObservation>& Observations(int frame) const {
    return index_.frames[static_cast<std::size_t>(frame)];
  }

  void Initialise() {
    const int n = index_.num_frames();
    int first = 0;
    while (first < n && static_cast<int>(Observations(first).size()) < 8) ++first;
    if (first >= n - 1) throw Error("tracks: no two frames with 8 or more observations");
    TracksTwoViewOptions two_view = options_.two_view;
    two_view.seed = options_.seed;
    switch (options_.init_mode) {
      case TracksInitMode::kFirstTwo:
        two_view.strict = false;
        two_view.min_parallax_deg = 0;
        TryPair(first, first + 1, two_view);
        break;
      case TracksInitMode::kFixed:
        two_view.min_parallax_deg = 0;
        if (options_.init_second_frame <= first || options_.init_second_frame >= n) {
          throw OptionError(fmt::format("init frame {}: the tracks have frames {}..{}",
                                        options_.init_second_frame, first + 1, n - 1));
        }
        TryPair(first, options_.init_second_frame, two_view);
        break;
      case TracksInitMode::kAuto:
        // Each later frame in the window; when none passes (the camera hovering or only
        // rotating), the first frame moves half a window on, as ORB-SLAM replaces its
        // initialisation reference.
        two_view.min_parallax_deg = options_.init_min_parallax_deg;
        for (; first < n - 1 && out_.init_second < 0;
             first += std::max(1, options_.init_search_frames / 2)) {
          if (static_cast<int>(Observations(first).size()) < 8) continue;
          for (int k = first + 1; k < n && k <= first + options_.init_search_frames; ++k) {
            if (TryPair(first, k, two_view)) break;
          }
        }
        break;
    }
    if (out_.init_second < 0) {
      const auto& last = out_.init_refused.back();
      throw Error(
          fmt::format("tracks: no initial pair ({} pair(s) tried; the last, frames {} and "
                      "{}: {})",
                      out_.init_refused.size(), last.first, last.second, last.reason));
    }
    first = out_.init_first;
    // The first camera is the world; |t| = 1 between the pair (the thesis's scale).
    AddKeyframe(first, SE3d(), "init");
    AddKeyframe(out_.init_second, out_.init.camera2_from_camera1, "init");
    for (std::size_t i = 0; i < out_.init.tracks.size(); ++i) {
      if (out_.init.triangulated[i]) {
        out_.points[static_cast<std::size_t>(out_.init.tracks[i])] = out_.init.points_camera1[i];
      }
    }
    for (int f : {first, out_.init_second}) {
      TracksFrameResult& fr = out_.frames[static_cast<std::size_t>(f)];
      fr.tracked = true;
      fr.observations = static_cast<int>(Observations(f).size());
      fr.map_matches = fr.inliers = out_.init.num_triangulated;
    }
    BundleAdjust({0, 1});
    last_keyframe_matches_ = out_.init.num_triangulated;
  }

  bool TryPair(int first, int second, const TracksTwoViewOptions& two_view) {
    TracksTwoViewResult r =
        ReconstructTwoViewTracks(Observations(first), Observations(second), camera_, two_view);
    if (!r.ok) {
      out_.init_refused.push_back({first, second, r.failure});
      return false;
    }
    out_.init_first = first;
    out_.init_second = second;
    out_.init = std::move(r);
    return true;
  }

  void AddKeyframe(int frame, const SE3d& camera_from_world, const std::string& reason) {
    keyframes_.push_back(frame);
    keyframe_poses_.push_back(camera_from_world);
    const int kf = static_cast<int>(keyframes_.size()) - 1;
    reference_[static_cast<std::size_t>(frame)] = kf;
    relative_[static_cast<std::size_t>(frame)] = SE3d();
    TracksFrameResult& fr = out_.frames[static_cast<std::size_t>(frame)];
    fr.keyframe = true;
    fr.keyframe_reason = reason;
    ++out_.keyframe_reasons[reason];
  }

  // The frame's observations of tracks that have a map point (index = observation index).
  std::vector<PnpCorrespondence> MappedCorrespondences(int frame) const {
    std::vector<PnpCorrespondence> mapped;
    const auto& obs = Observations(frame);
    for (std::size_t i = 0; i < obs.size(); ++i) {
      const auto& point = out_.points[static_cast<std::size_t>(obs[i].track)];
      if (!point) continue;
      mapped.push_back({obs[i].uv, options_.two_view.sigma * options_.two_view.sigma, *point,
                        static_cast<int>(i)});
    }
    return mapped;
  }

  // Motion-only refinement from `start`; *refined holds the correspondences (null block =
  // outlier at the result) and *inliers their inlier count.
  SE3d RefinePose(const std::vector<PnpCorrespondence>& mapped, const SE3d& start,
                  std::vector<PoseCorrespondence>* refined, int* inliers) const {
    refined->clear();
    refined->reserve(mapped.size());
    for (const PnpCorrespondence& c : mapped) {
      PoseCorrespondence& p = refined->emplace_back();
      p.keypoint = c.index;
      p.p_world = c.point_world;
      p.obs = Eigen::Vector3d(c.uv.x(), c.uv.y(), -1.0);
      p.inv_sigma2 = inv_sigma2_;
    }
    const SE3d pose = SolvePose(camera_, start, refined, PoseOptimizerOptions{});
    *inliers = static_cast<int>(std::count_if(refined->begin(), refined->end(),
                                              [](const PoseCorrespondence& c) { return c.block; }));
    return pose;
  }

  void ProcessFrame(int k, bool may_be_keyframe) {
    const Clock::time_point t0 = Clock::now();
    TracksFrameResult& fr = out_.frames[static_cast<std::size_t>(k)];
    const auto& obs = Observations(k);
    fr.observations = static_cast<int>(obs.size());
    // Prediction: the latest tracked pose (the processor has no motion model in the thesis).
    const SE3d predicted = last_tracked_ >= 0 ? CurrentPose(last_tracked_) : KeyframePose(0);
    const std::vector<PnpCorrespondence> pnp = MappedCorrespondences(k);
    fr.map_matches = static_cast<int>(pnp.size());
    if (fr.map_matches < options_.min_tracked) {
      ++out_.lost_frames;
      out_.seconds_tracking += SecondsSince(t0);
      return;
    }
    // PnP: RANSAC (P3P) for a start robust to outlier tracks, then motion-only refinement.
    SE3d start = predicted;
    PnpRansacOptions ransac;
    ransac.min_inliers = options_.min_tracked;
    ransac.seed = options_.seed + static_cast<std::uint64_t>(k);
    PnpRansac solver(pnp, camera_, ransac);
    const PnpResult found = solver.Iterate(ransac.max_iterations);
    if (found.found) start = found.camera_from_world;
    std::vector<PoseCorrespondence> refine;
    const SE3d pose = RefinePose(pnp, start, &refine, &fr.inliers);
    out_.seconds_tracking += SecondsSince(t0);
    if (fr.inliers < options_.min_tracked) {
      ++out_.lost_frames;
      return;
    }
    fr.tracked = true;
    last_tracked_ = k;
    if (may_be_keyframe) {
      const std::string reason = DecideKeyframe(k, pose, refine);
      if (!reason.empty()) {
        const Clock::time_point t1 = Clock::now();
        AddKeyframe(k, pose, reason);
        Triangulate(static_cast<int>(keyframes_.size()) - 1);
        std::vector<int> window;
        const int count = static_cast<int>(keyframes_.size());
        for (int i = std::max(0, count - options_.local_window); i < count; ++i) {
          window.push_back(i);
        }
        BundleAdjust(window);
        ++out_.local_ba_runs;
        last_keyframe_matches_ = fr.inliers;
        out_.seconds_mapping += SecondsSince(t1);
        return;
      }
    }
    // A frame between the initial pair follows the nearer of its two keyframes; a later one
    // the latest keyframe.
    int ref = static_cast<int>(keyframes_.size()) - 1;
    if (!may_be_keyframe) ref = k - out_.init_first <= out_.init_second - k ? 0 : 1;
    reference_[static_cast<std::size_t>(k)] = ref;
    relative_[static_cast<std::size_t>(k)] = pose * KeyframePose(ref).Inverse();
  }

  // The rule's reason, or "" for no keyframe.
  std::string DecideKeyframe(int k, const SE3d& pose, const std::vector<PoseCorrespondence>& c) {
    const TracksFrameResult& fr = out_.frames[static_cast<std::size_t>(k)];
    const int last_frame = keyframes_.back();
    const auto& last_obs = Observations(last_frame);
    if (fr.inliers < options_.starving_share * last_keyframe_matches_) return "starving";
    if (options_.keyframe_rule == TracksKeyframeRule::kRatio) {
      if (k - last_frame < options_.ratio_min_frames) return "";
      int new_tracks = 0;
      for (const IndexedObservation& o : Observations(k)) {
        if (!out_.points[static_cast<std::size_t>(o.track)] && FindObservation(last_obs, o.track)) {
          ++new_tracks;
        }
      }
      return fr.inliers < options_.ratio_max * new_tracks ? "ratio" : "";
    }
    SelectorInput in;
    in.sensor = Sensor::kMonocular;
    in.frame_id = k;
    in.t_ns = std::llround(index_.times_s[static_cast<std::size_t>(k)] * 1e9);
    in.fps = fps_;
    in.image_width = tracks_.width;
    in.image_height = tracks_.height;
    in.fx = camera_.fx;
    in.fy = camera_.fy;
    in.cx = camera_.cx;
    in.cy = camera_.cy;
    in.camera_from_world = pose;
    in.inliers = fr.inliers;
    const auto& obs = Observations(k);
    for (const PoseCorrespondence& p : c) {
      if (!p.block) continue;
      SelectorPoint& s = in.points.emplace_back();
      const IndexedObservation& o = obs[static_cast<std::size_t>(p.keypoint)];
      s.id = o.track;
      s.position_world = p.p_world;
      s.uv = o.uv;
      s.keypoint_index = p.keypoint;
      s.in_last_keyframe = FindObservation(last_obs, o.track) != nullptr;
    }
    in.keyframes_in_map = static_cast<int>(keyframes_.size());
    in.last_keyframe_id = static_cast<KeyFrameId>(keyframes_.size() - 1);
    in.last_keyframe_frame_id = last_frame;
    in.last_keyframe_t_ns =
        std::llround(index_.times_s[static_cast<std::size_t>(last_frame)] * 1e9);
    in.last_keyframe_camera_from_world = keyframe_poses_.back();
    const SelectorDecision d = selector_->Decide(in);
    return d.insert ? std::string(TracksKeyframeRuleName(options_.keyframe_rule)) : "";
  }

  // Linear triangulation of the new keyframe's tracks that have no point yet, each with the
  // earlier keyframe that sees it under the widest ray angle.
  void Triangulate(int kf) {
    const int frame = keyframes_[static_cast<std::size_t>(kf)];
    const SE3d& pose = KeyframePose(kf);
    const Eigen::Matrix3d rotation_t = pose.RotationMatrix().transpose();
    const double gate2 = 5.991 / inv_sigma2_;
    for (const IndexedObservation& o : Observations(frame)) {
      auto& point = out_.points[static_cast<std::size_t>(o.track)];
      if (point) continue;
      const Eigen::Vector3d ray = rotation_t * camera_.Bearing(o.uv);
      int best = -1;
      double best_angle = 0;
      const IndexedObservation* best_obs = nullptr;
      for (int other = 0; other < kf; ++other) {
        const IndexedObservation* o2 =
            FindObservation(Observations(keyframes_[static_cast<std::size_t>(other)]), o.track);
        if (!o2) continue;
        const Eigen::Vector3d ray2 =
            KeyframePose(other).RotationMatrix().transpose() * camera_.Bearing(o2->uv);
        const double angle = RayAngleDeg(ray, ray2);
        if (angle > best_angle) {
          best_angle = angle;
          best = other;
          best_obs = o2;
        }
      }
      if (best < 0 || best_angle < options_.min_triangulation_parallax_deg) continue;
      // In the other keyframe's camera: it is camera 1 of the two-view triangulation.
      const SE3d& pose1 = KeyframePose(best);
      const SE3d relative = pose * pose1.Inverse();
      two_view::Motion motion;
      motion.rotation = relative.RotationMatrix();
      motion.translation = relative.translation();
      const Eigen::Vector2d x1((best_obs->uv.x() - camera_.cx) / camera_.fx,
                               (best_obs->uv.y() - camera_.cy) / camera_.fy);
      const Eigen::Vector2d x2((o.uv.x() - camera_.cx) / camera_.fx,
                               (o.uv.y() - camera_.cy) / camera_.fy);
      const Eigen::Vector3d p1 = two_view::TriangulateLinear(x1, x2, motion);
      if (!p1.allFinite() || p1.z() <= 0) continue;
      const Eigen::Vector3d p2 = motion.rotation * p1 + motion.translation;
      if (p2.z() <= 0) continue;
      if ((camera_.Project(p1) - best_obs->uv).squaredNorm() > gate2 ||
          (camera_.Project(p2) - o.uv).squaredNorm() > gate2) {
        continue;
      }
      point = pose1.Inverse() * p1;
    }
  }

  // Bundle adjustment of the keyframes in `free` (indices into keyframes_, ascending) and the
  // points they see; other keyframes seeing those points enter fixed, and keyframe 0 is always
  // fixed (the gauge). Outlier observations leave later problems; points left with fewer than
  // two observations are removed (their tracks may be triangulated again).
  void BundleAdjust(const std::vector<int>& free) {
    BundleProblem problem;
    problem.fx = camera_.fx;
    problem.fy = camera_.fy;
    problem.cx = camera_.cx;
    problem.cy = camera_.cy;
    std::vector<int> problem_of_kf(keyframes_.size(), -1);
    std::vector<int> problem_of_point(out_.points.size(), -1);
    std::vector<int> point_tracks;
    for (int kf : free) {
      for (const IndexedObservation& o : Observations(keyframes_[static_cast<std::size_t>(kf)])) {
        if (!out_.points[static_cast<std::size_t>(o.track)] ||
            problem_of_point[static_cast<std::size_t>(o.track)] >= 0) {
          continue;
        }
        problem_of_point[static_cast<std::size_t>(o.track)] = static_cast<int>(point_tracks.size());
        point_tracks.push_back(o.track);
        problem.points.push_back(
            {static_cast<MapPointId>(o.track), *out_.points[static_cast<std::size_t>(o.track)]});
      }
    }
    if (point_tracks.empty()) return;
    std::vector<bool> is_free(keyframes_.size(), false);
    for (int kf : free) is_free[static_cast<std::size_t>(kf)] = true;
    std::vector<std::pair<int, int>> observation_keys;  // (keyframe, track) per observation
    for (std::size_t kf = 0; kf < keyframes_.size(); ++kf) {
      for (const IndexedObservation& o : Observations(keyframes_[kf])) {
        const int pi = problem_of_point[static_cast<std::size_t>(o.track)];
        if (pi < 0 || outliers_.count({static_cast<int>(kf), o.track})) continue;
        if (problem_of_kf[kf] < 0) {
          problem_of_kf[kf] = static_cast<int>(problem.keyframes.size());
          problem.keyframes.push_back(
              {static_cast<KeyFrameId>(kf), keyframe_poses_[kf], !is_free[kf] || kf == 0});
        }
        BundleProblem::ObservationState s{problem_of_kf[kf], pi, 0, o.uv, -1.0, inv_sigma2_};
        problem.observations.push_back(s);
        observation_keys.emplace_back(static_cast<int>(kf), o.track);
      }
    }
    BundleAdjustmentOptions ba;
    const BundleResult result = SolveBundle(problem, ba);
    for (std::size_t i = 0; i < problem.keyframes.size(); ++i) {
      if (!problem.keyframes[i].fixed) {
        keyframe_poses_[static_cast<std::size_t>(problem.keyframes[i].keyframe_id)] =
            result.camera_from_world[i];
      }
    }
    for (std::size_t i = 0; i < point_tracks.size(); ++i) {
      out_.points[static_cast<std::size_t>(point_tracks[i])] = result.points_world[i];
    }
    for (int o : result.outlier_observations) {
      outliers_.insert(observation_keys[static_cast<std::size_t>(o)]);
    }
    // Points with fewer than two inlier observations say nothing about depth.
    std::vector<int> inlier_count(point_tracks.size(), 0);
    for (std::size_t i = 0; i < problem.observations.size(); ++i) {
      if (!outliers_.count(observation_keys[i])) {
        ++inlier_count[static_cast<std::size_t>(problem.observations[i].point_index)];
      }
    }
    for (std::size_t i = 0; i < point_tracks.size(); ++i) {
      if (inlier_count[i] < 2) out_.points[static_cast<std::size_t>(point_tracks[i])].reset();
    }
  }

  void Finish() {
    for (std::size_t k = 0; k < out_.frames.size(); ++k) {
      TracksFrameResult& fr = out_.frames[k];
      if (!fr.tracked) continue;
      fr.camera_from_world = CurrentPose(static_cast<int>(k));
      if (fr.keyframe || !options_.refine_frames) continue;
      // The pose against the final map: a frame tracked before the last bundle adjustments
      // moved its keyframe and points only follows its keyframe rigidly.
      const std::vector<PnpCorrespondence> mapped = MappedCorrespondences(static_cast<int>(k));
      if (static_cast<int>(mapped.size()) < options_.min_tracked) continue;
      std::vector<PoseCorrespondence> refine;
      int inliers = 0;
      const SE3d pose = RefinePose(mapped, fr.camera_from_world, &refine, &inliers);
      if (inliers >= options_.min_tracked) fr.camera_from_world = pose;
    }
    out_.num_keyframes = static_cast<int>(keyframes_.size());
    // Frames before the first initial frame never had a chance: count them as lost too.
    out_.lost_frames += out_.init_first;
  }

  const TrackSet& tracks_;
  const TrackIndex& index_;
  TracksReconstructionOptions options_;
  PinholeIntrinsics camera_;
  double inv_sigma2_ = 1;
  double fps_ = 20;
  std::unique_ptr<KeyframeSelector> selector_;
  TracksReconstruction out_;
  std::vector<int> keyframes_;              // frame of each keyframe
  std::vector<SE3d> keyframe_poses_;        // camera_from_world of each keyframe
  std::vector<int> reference_;              // per frame: its keyframe (-1: none)
  std::vector<SE3d> relative_;              // per frame: camera_from_keyframe-camera
  std::set<std::pair<int, int>> outliers_;  // (keyframe, track) observations BA rejected
  int last_tracked_ = -1;
  int last_keyframe_matches_ = 0;
};

}  // namespace

TracksReconstruction ReconstructFromTracks(const TrackSet& tracks, const TrackIndex& index,
                                           const TracksReconstructionOptions& options,
                                           const std::function<void(int, int)>& progress) {
  options.Check();
  return Reconstructor(tracks, index, options).Run(progress);
}

std::vector<double> FrameReprojectionErrors(const TracksReconstruction& r, const TrackIndex& index,
                                            const PinholeIntrinsics& camera, int frame) {
  std::vector<double> errors;
  const TracksFrameResult& fr = r.frames.at(static_cast<std::size_t>(frame));
  if (!fr.tracked) return errors;
  for (const IndexedObservation& o : index.frames[static_cast<std::size_t>(frame)]) {
    const auto& p = r.points[static_cast<std::size_t>(o.track)];
    if (!p) continue;
    const Eigen::Vector3d c = fr.camera_from_world * *p;
    if (c.z() <= 0) continue;  // behind the camera: no pixel (BA removes such points)
    errors.push_back((camera.Project(c) - o.uv).norm());
  }
  return errors;
}

}  // namespace pkslam
