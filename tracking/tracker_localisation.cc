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
  frame.has_velocity = frames_.velocity.has_value();
  frame.after_relocalisation_gap = !frames_.JustRelocalised();
  frame.odometry_possible = !IsMonocular(rig_->sensor);
  // The motion model runs only after a tracked frame, which has a record.
  const LocalisationMoves moves{
      [this] { return map_tracker_.TrackWithMotionModel(records_.back(), &frames_); },
      [this] { return map_tracker_.TrackReferenceKeyFrame(&frames_); },
      [this] { return map_tracker_.Relocalise(&frames_); },
      [this] { return map_tracker_.TrackLocalMap(state_, ImuReady(), &frames_); }};
  const bool ok = localisation_.Track(frame, moves, &frames_.current);
  state_ = ok ? TrackingState::kOk : TrackingState::kLost;
  return ok;
}

}  // namespace pkslam
