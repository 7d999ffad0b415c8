// Localisation-only tracking (ORB-SLAM's localisation mode) against a loaded map: no keyframes,
// no points, no map resets. A frame that cannot be tracked is relocalised; where the map has too
// few points in view, stereo and RGB-D frames go on by visual odometry (temporary points from
// the previous frame's depth) while every frame also tries to relocalise, and a relocalisation
// wins. Without it a 10 s map lost the camera for good the moment it looked elsewhere.
#include <cstdint>
#include <optional>
#include <vector>

#include "core/util/error.h"
#include "map_model/map.h"
#include "map_model/map_point.h"
#include "tracking/tracker.h"

namespace pkslam {
namespace {

// What tracking changes in a frame: its pose and its matches. Kept aside to restore an odometry
// pose after a failed map search (a copy of the whole frame would take its keypoints and
// descriptors too, on every localised frame).
struct PoseAndMatches {
  SE3d camera_from_world;
  std::vector<MapPointPtr> map_points;
  std::vector<std::uint8_t> outliers;

  static PoseAndMatches Of(const Frame& frame) {
    return {frame.camera_from_world(), frame.map_points, frame.outliers};
  }
  void RestoreTo(Frame* frame) const {
    frame->SetPose(camera_from_world);
    frame->map_points = map_points;
    frame->outliers = outliers;
  }
};

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
    const bool motion = velocity_ && TrackWithMotionModel() &&
                        InlierMatches(current_, /*map_only=*/false) >= kMinOdometryMatches;
    std::optional<PoseAndMatches> odometry;
    if (motion) odometry = PoseAndMatches::Of(current_);
    if (Relocalize() && TrackLocalMap()) {
      visual_odometry_ = false;
      return true;
    }
    if (odometry) {
      odometry->RestoreTo(&current_);
      if (InlierMatches(current_, /*map_only=*/true) >= kMinMapMatches && TrackLocalMap()) {
        visual_odometry_ = false;  // back in the map
        return true;
      }
      odometry->RestoreTo(&current_);
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
    // The map may be running out of view: then go on by visual odometry if the frame-to-frame
    // pose holds (stereo / RGB-D).
    std::optional<PoseAndMatches> before_local_map;
    if (odometry_possible && velocity_ &&
        InlierMatches(current_, /*map_only=*/false) >= kMinOdometryMatches) {
      before_local_map = PoseAndMatches::Of(current_);
    }
    if (TrackLocalMap()) return true;
    if (before_local_map) {
      before_local_map->RestoreTo(&current_);
      visual_odometry_ = true;
      return true;
    }
  }
  state_ = TrackingState::kLost;
  return false;
}

}  // namespace pkslam
