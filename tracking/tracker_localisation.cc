// Localisation-only tracking (ORB-SLAM's localisation mode) against a loaded map: no keyframes,
// no points, no map resets. A frame that cannot be tracked is relocalised; where the map has too
// few points in view, stereo and RGB-D frames go on by visual odometry (temporary points from
// the previous frame's depth) while every frame also tries to relocalise, and a relocalisation
// wins. Without it a 10 s map lost the camera for good the moment it looked elsewhere.
#include "core/util/error.h"
#include "map_model/map.h"
#include "map_model/map_point.h"
#include "tracking/tracker.h"

namespace pkslam {
namespace {

// Inlier matches to points of the map (temporary visual-odometry points have no observations).
int MapMatches(const Frame& frame) {
  int n = 0;
  for (int i = 0; i < frame.size(); ++i) {
    const auto& mp = frame.map_points[i];
    const bool outlier = i < static_cast<int>(frame.outliers.size()) && frame.outliers[i];
    if (mp && !outlier && mp->NumObservations() > 0) ++n;
  }
  return n;
}

// All inlier matches (map and temporary points).
int Matches(const Frame& frame) {
  int n = 0;
  for (int i = 0; i < frame.size(); ++i) {
    const bool outlier = i < static_cast<int>(frame.outliers.size()) && frame.outliers[i];
    if (frame.map_points[i] && !outlier) ++n;
  }
  return n;
}

// Map matches below which a frame counts as tracked by visual odometry, and the matches a
// visual-odometry pose needs in all (ORB-SLAM: 10 and 20).
constexpr int kMinMapMatches = 10;
constexpr int kMinOdometryMatches = 20;

}  // namespace

void Tracker::StartLocalisation() {
  PKSLAM_CHECK(options_.localise_only, "StartLocalisation needs TrackingOptions::localise_only");
  StartOver();
  state_ = TrackingState::kLost;
  visual_odometry_ = false;
}

bool Tracker::TrackLocalisationOnly() {
  const bool odometry_possible = !IsMonocular(rig_->sensor);
  if (state_ != TrackingState::kOk) {
    // No pose to go on from: only the map can say where the camera is.
    visual_odometry_ = false;
    const bool ok = Relocalize() && TrackLocalMap();
    state_ = ok ? TrackingState::kOk : TrackingState::kLost;
    return ok;
  }
  if (visual_odometry_) {
    // Visual odometry from the last frame, and a relocalisation attempt; the map wins.
    const bool motion =
        velocity_ && TrackWithMotionModel() && Matches(current_) >= kMinOdometryMatches;
    const Frame odometry = current_;
    if (Relocalize() && TrackLocalMap()) {
      visual_odometry_ = false;
      return true;
    }
    if (motion) {
      current_ = odometry;
      if (MapMatches(current_) >= kMinMapMatches && TrackLocalMap()) {
        visual_odometry_ = false;  // back in the map
        return true;
      }
      current_ = odometry;
      visual_odometry_ = true;
      return true;
    }
    state_ = TrackingState::kLost;
    visual_odometry_ = false;
    return false;
  }
  bool ok = false;
  if (velocity_ && current_.id() >= last_reloc_frame_id_ + 2) ok = TrackWithMotionModel();
  if (!ok) ok = TrackReferenceKeyFrame();
  if (ok) {
    const Frame before_local_map = current_;
    if (TrackLocalMap()) return true;
    // The map is running out of view: go on by visual odometry if the frame-to-frame pose
    // holds (stereo / RGB-D).
    if (odometry_possible && velocity_ && Matches(before_local_map) >= kMinOdometryMatches) {
      current_ = before_local_map;
      visual_odometry_ = true;
      return true;
    }
  }
  state_ = TrackingState::kLost;
  return false;
}

}  // namespace pkslam
