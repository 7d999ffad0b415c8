// Tracker::Relocalize: the tracker's bookkeeping around RelocaliseFrame
// (tracking/relocaliser.h). Runs under the Atlas shared lock taken in Tracker::Track.
#include "core/util/log.h"
#include "tracking/relocaliser.h"
#include "tracking/tracker.h"

namespace pkslam {

bool Tracker::Relocalize() {
  const KeyFrameDatabase* database = atlas_->database();
  if (database == nullptr) return false;
  RelocalisationOptions options;
  options.wide = failed_relocalisations_ >= options_.relocalisation_widen_after;
  options.wide_candidates = options_.relocalisation_wide_candidates;
  options.seed = MixSeed(options_.seed, static_cast<std::uint64_t>(current_.id()));
  options.pose = options_.pose;
  if (failed_relocalisations_ == options_.relocalisation_widen_after) {
    PKSLAM_LOG_INFO("relocalisation: {} attempts in a row failed (t = {:.3f} s); widening the "
                    "place search",
                    failed_relocalisations_, current_.t_s());
  }
  ++failed_relocalisations_;  // until the success below
  const RelocalisationResult result =
      RelocaliseFrame(*database, atlas_->current_map(), *vocabulary_, *rig_, options, &current_);
  if (!result.success) {
    if (result.places > 0) {
      PKSLAM_LOG_DEBUG(
          "relocalisation failed at t = {:.3f} s: {} place(s), {} with 15+ BoW matches{}",
          current_.t_s(), result.places, result.candidates, options.wide ? " (wide)" : "");
    }
    return false;
  }
  last_reloc_frame_id_ = current_.id();
  PKSLAM_LOG_INFO("relocalised at t = {:.3f} s against keyframe {} ({} inliers)", current_.t_s(),
                  result.keyframe, result.inliers);
  ++relocalisations_;
  failed_relocalisations_ = 0;
  return true;
}

}  // namespace pkslam
