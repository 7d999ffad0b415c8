// Localisation-only tracking (ORB-SLAM3's localisation mode) against a loaded map: no
// keyframes, no points, no map resets; a frame that cannot be tracked is relocalised.
#include "core/util/error.h"
#include "map_model/map.h"
#include "tracking/tracker.h"

namespace pkslam {

void Tracker::StartLocalisation() {
  PKSLAM_CHECK(options_.localise_only, "StartLocalisation needs TrackingOptions::localise_only");
  StartOver();
  state_ = TrackingState::kLost;
}

bool Tracker::TrackLocalisationOnly() {
  bool ok = false;
  if (state_ == TrackingState::kOk) {
    if (velocity_ && current_.id() >= last_reloc_frame_id_ + 2) ok = TrackWithMotionModel();
    if (!ok) ok = TrackReferenceKeyFrame();
  } else {
    ok = Relocalize();
  }
  if (ok) ok = TrackLocalMap();
  state_ = ok ? TrackingState::kOk : TrackingState::kLost;
  return ok;
}

}  // namespace pkslam
