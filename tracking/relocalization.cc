// Relocalisation (ORB-SLAM3's Tracking::Relocalization): keyframes that look like the frame
// (BoW) are matched to it, a PnP RANSAC per candidate proposes poses, and a pose is accepted
// once pose optimisation and projection searches confirm it with >= 50 inliers. Runs under
// the Atlas shared lock taken in Tracker::Track.
#include <unordered_set>

#include "core/bow/vocabulary.h"
#include "core/util/log.h"
#include "map_model/estimation/ransac_inputs.h"
#include "map_model/keyframe.h"
#include "map_model/keyframe_database.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"
#include "tracking/pose_optimizer.h"
#include "tracking/tracker.h"

namespace pkslam {
namespace {

struct Candidate {
  KeyFrame* keyframe;
  std::vector<MapPointPtr> matches;  // per frame keypoint
  std::unique_ptr<PnpRansac> pnp;
  bool discarded = false;
};

int RemoveOutliers(Frame* frame) {
  int kept = 0;
  for (int i = 0; i < frame->size(); ++i) {
    if (!frame->map_points[i]) continue;
    if (frame->outliers[i]) {
      frame->map_points[i].reset();
      frame->outliers[i] = 0;
    } else {
      ++kept;
    }
  }
  return kept;
}

std::vector<MapPoint*> FoundPoints(const Frame& frame) {
  std::vector<MapPoint*> out;
  for (const auto& mp : frame.map_points) {
    if (mp) out.push_back(mp.get());
  }
  return out;
}

}  // namespace

bool Tracker::Relocalize() {
  KeyFrameDatabase* database = atlas_->database();
  if (database == nullptr) return false;
  current_.ComputeBoW(*vocabulary_);
  // After repeated failure the view is likely further from every keyframe than the usual
  // thresholds allow (a localisation map of 10 s seen from elsewhere in the room): widen.
  const bool wide = failed_relocalisations_ >= options_.relocalisation_widen_after;
  if (failed_relocalisations_ == options_.relocalisation_widen_after) {
    PKSLAM_LOG_INFO("relocalisation: {} attempts in a row failed (t = {:.3f} s); widening the "
                    "place search",
                    failed_relocalisations_, current_.t_s());
  }
  KeyFrameDatabaseOptions wide_ratios;
  wide_ratios.min_common_words_ratio = 0.5;
  wide_ratios.min_group_score_ratio = 0.5;
  const auto places =
      wide ? database->DetectRelocalisationCandidates(
                 current_, atlas_->current_map(), wide_ratios,
                 static_cast<std::size_t>(options_.relocalisation_wide_candidates))
           : database->DetectRelocalisationCandidates(current_, atlas_->current_map());
  ++failed_relocalisations_;  // until the success below
  if (places.empty()) return false;

  const OrbMatcher bow_matcher(0.75, true);
  const PinholeIntrinsics camera{rig_->fx, rig_->fy, rig_->cx, rig_->cy};
  std::vector<Candidate> candidates;
  for (const auto& place : places) {
    if (place.keyframe->IsBad()) continue;
    Candidate c{place.keyframe, {}, nullptr};
    if (bow_matcher.SearchByBoW(*place.keyframe, current_, &c.matches) < 15) continue;
    PnpRansacOptions pnp;
    pnp.seed = MixSeed(options_.seed, static_cast<std::uint64_t>(current_.id()));
    c.pnp = std::make_unique<PnpRansac>(MakePnpCorrespondences(current_, c.matches), camera, pnp);
    candidates.push_back(std::move(c));
  }

  const OrbMatcher projection_matcher(0.9, true);
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
      current_.SetPose(pnp.camera_from_world);
      std::fill(current_.map_points.begin(), current_.map_points.end(), nullptr);
      const auto& correspondences = c.pnp->correspondences();
      for (std::size_t k = 0; k < correspondences.size(); ++k) {
        if (pnp.inliers[k])
          current_.map_points[correspondences[k].index] = c.matches[correspondences[k].index];
      }
      current_.outliers.assign(current_.size(), 0);
      int good = OptimizePose(&current_, options_.pose);
      if (good < 10) continue;
      good = RemoveOutliers(&current_);
      // Too few inliers: look for more in the candidate by projection, with a wide window
      // first and a narrow one once the pose is better.
      if (good < 50) {
        const int more = projection_matcher.SearchByProjection(&current_, *c.keyframe,
                                                               FoundPoints(current_), 10, 100);
        if (good + more >= 50) {
          current_.outliers.assign(current_.size(), 0);
          good = OptimizePose(&current_, options_.pose);
          if (good > 30 && good < 50) {
            const int again = projection_matcher.SearchByProjection(&current_, *c.keyframe,
                                                                    FoundPoints(current_), 3, 64);
            if (good + again >= 50) {
              current_.outliers.assign(current_.size(), 0);
              good = OptimizePose(&current_, options_.pose);
            }
          }
          good = RemoveOutliers(&current_);
        }
      }
      if (good >= 50) {
        last_reloc_frame_id_ = current_.id();
        PKSLAM_LOG_INFO("relocalised at t = {:.3f} s against keyframe {} ({} inliers)",
                        current_.t_s(), c.keyframe->id(), good);
        ++relocalisations_;
        failed_relocalisations_ = 0;
        return true;
      }
    }
  }
  PKSLAM_LOG_DEBUG("relocalisation failed at t = {:.3f} s: {} place(s), {} with 15+ BoW matches{}",
                   current_.t_s(), places.size(), candidates.size(), wide ? " (wide)" : "");
  std::fill(current_.map_points.begin(), current_.map_points.end(), nullptr);
  return false;
}

}  // namespace pkslam
