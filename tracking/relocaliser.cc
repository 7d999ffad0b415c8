#include "tracking/relocaliser.h"

#include <algorithm>
#include <memory>
#include <vector>

#include "core/bow/vocabulary.h"
#include "core/util/log.h"
#include "map_model/estimation/ransac_inputs.h"
#include "map_model/keyframe.h"
#include "map_model/keyframe_database.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"
#include "tracking/frame_tracking.h"

namespace pkslam {
namespace {

struct Candidate {
  KeyFrame* keyframe;
  std::vector<MapPointPtr> matches;  // per frame keypoint
  std::unique_ptr<PnpRansac> pnp;
  bool discarded = false;
};

// DiscardOutliers, counting every match kept.
int RemoveOutliers(Frame* frame) {
  DiscardOutliers(frame);
  return static_cast<int>(std::count_if(frame->map_points.begin(), frame->map_points.end(),
                                        [](const MapPointPtr& mp) { return mp != nullptr; }));
}

std::vector<MapPoint*> FoundPoints(const Frame& frame) {
  std::vector<MapPoint*> out;
  for (const auto& mp : frame.map_points) {
    if (mp) out.push_back(mp.get());
  }
  return out;
}

// Confirms a PnP pose of `frame` against candidate `c`: pose optimisation, then, with too few
// inliers, more matches by projection from the candidate (a wide window, then a narrow one
// once the pose is better). Returns the inliers kept.
int ConfirmPose(const Candidate& c, const PnpResult& pnp, const PoseOptimizerOptions& options,
                Frame* frame) {
  const OrbMatcher projection_matcher(0.9, true);
  frame->SetPose(pnp.camera_from_world);
  std::fill(frame->map_points.begin(), frame->map_points.end(), nullptr);
  const auto& correspondences = c.pnp->correspondences();
  for (std::size_t k = 0; k < correspondences.size(); ++k) {
    if (pnp.inliers[k])
      frame->map_points[correspondences[k].index] = c.matches[correspondences[k].index];
  }
  frame->outliers.assign(frame->size(), 0);
  int good = OptimizePose(frame, options);
  if (good < 10) return good;
  good = RemoveOutliers(frame);
  if (good >= kMinRelocalisationInliers) return good;
  const int more =
      projection_matcher.SearchByProjection(frame, *c.keyframe, FoundPoints(*frame), 10, 100);
  if (good + more < kMinRelocalisationInliers) return good;
  frame->outliers.assign(frame->size(), 0);
  good = OptimizePose(frame, options);
  if (good > 30 && good < kMinRelocalisationInliers) {
    const int again =
        projection_matcher.SearchByProjection(frame, *c.keyframe, FoundPoints(*frame), 3, 64);
    if (good + again >= kMinRelocalisationInliers) {
      frame->outliers.assign(frame->size(), 0);
      good = OptimizePose(frame, options);
    }
  }
  return RemoveOutliers(frame);
}

}  // namespace

RelocalisationResult RelocaliseFrame(const KeyFrameDatabase& database, const Map* map,
                                     const Vocabulary& vocabulary, const CameraRig& rig,
                                     const RelocalisationOptions& options, Frame* frame) {
  RelocalisationResult result;
  frame->ComputeBoW(vocabulary);
  KeyFrameDatabaseOptions wide_ratios;
  wide_ratios.min_common_words_ratio = 0.5;
  wide_ratios.min_group_score_ratio = 0.5;
  const auto places = options.wide ? database.DetectRelocalisationCandidates(
                                         *frame, map, wide_ratios,
                                         static_cast<std::size_t>(options.wide_candidates))
                                   : database.DetectRelocalisationCandidates(*frame, map);
  result.places = places.size();
  if (places.empty()) return result;

  const OrbMatcher bow_matcher(0.75, true);
  const PinholeIntrinsics camera{rig.fx, rig.fy, rig.cx, rig.cy};
  std::vector<Candidate> candidates;
  for (const auto& place : places) {
    if (place.keyframe->IsBad()) continue;
    Candidate c{place.keyframe, {}, nullptr};
    if (bow_matcher.SearchByBoW(*place.keyframe, *frame, &c.matches) < 15) continue;
    PnpRansacOptions pnp;
    pnp.seed = options.seed;
    c.pnp = std::make_unique<PnpRansac>(MakePnpCorrespondences(*frame, c.matches), camera, pnp);
    candidates.push_back(std::move(c));
  }
  result.candidates = candidates.size();

  int remaining = static_cast<int>(candidates.size());
  while (remaining > 0) {
    for (Candidate& c : candidates) {
      if (c.discarded) continue;
      const PnpResult pnp = c.pnp->Iterate(5);
      if (pnp.exhausted && !pnp.found) {
        c.discarded = true;
        --remaining;
        continue;
      }
      if (!pnp.found) continue;
      const int good = ConfirmPose(c, pnp, options.pose, frame);
      if (good >= kMinRelocalisationInliers) {
        result.success = true;
        result.keyframe = c.keyframe->id();
        result.inliers = good;
        return result;
      }
    }
  }
  std::fill(frame->map_points.begin(), frame->map_points.end(), nullptr);
  return result;
}

RelocalisationResult RelocalisationAttempts::Try(const KeyFrameDatabase& database, const Map* map,
                                                 const Vocabulary& vocabulary, const CameraRig& rig,
                                                 std::uint64_t seed, Frame* frame) {
  RelocalisationOptions options;
  options.wide = NextIsWide();
  options.wide_candidates = wide_candidates_;
  options.seed = seed;
  options.pose = pose_;
  if (failures_in_a_row_ == widen_after_) {
    PKSLAM_LOG_INFO(
        "relocalisation: {} attempts in a row failed (t = {:.3f} s); widening the "
        "place search",
        failures_in_a_row_, frame->t_s());
  }
  const RelocalisationResult result =
      RelocaliseFrame(database, map, vocabulary, rig, options, frame);
  if (!result.success) {
    ++failures_in_a_row_;
    if (result.places > 0) {
      PKSLAM_LOG_DEBUG(
          "relocalisation failed at t = {:.3f} s: {} place(s), {} with 15+ BoW matches{}",
          frame->t_s(), result.places, result.candidates, options.wide ? " (wide)" : "");
    }
    return result;
  }
  PKSLAM_LOG_INFO("relocalised at t = {:.3f} s against keyframe {} ({} inliers)", frame->t_s(),
                  result.keyframe, result.inliers);
  ++successes_;
  failures_in_a_row_ = 0;
  return result;
}

}  // namespace pkslam
