// Tracker: localisation only, through its LocalisationTracking part
// (tracking/localisation_tracking.h: the policy and its tests).
#include "core/util/error.h"
#include "tracking/tracker.h"

namespace pkslam {

void Tracker::StartLocalisation() {
  PKSLAM_CHECK(options_.localise_only, "StartLocalisation needs TrackingOptions::localise_only");
  StartOver();
  state_ = TrackingState::kLost;
  localisation_.Restart();
}

bool Tracker::TrackLocalisationOnly() {
  LocalisationFrame frame;
  frame.last_tracked = state_ == TrackingState::kOk;
  frame.has_velocity = velocity_.has_value();
  frame.after_relocalisation_gap = current_.id() >= last_reloc_frame_id_ + 2;
  frame.odometry_possible = !IsMonocular(rig_->sensor);
  const LocalisationMoves moves{
      [this] { return TrackWithMotionModel(); }, [this] { return TrackReferenceKeyFrame(); },
      [this] { return Relocalize(); }, [this] { return TrackLocalMap(); }};
  const bool ok = localisation_.Track(frame, moves, &current_);
  state_ = ok ? TrackingState::kOk : TrackingState::kLost;
  return ok;
}

}  // namespace pkslam
