#include "tracking/localisation_tracking.h"

#include <algorithm>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "map_model/map_point.h"

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

int InlierMatches(const Frame& frame, bool map_only) {
  int n = 0;
  for (int i = 0; i < frame.size(); ++i) {
    const auto& mp = frame.map_points[i];
    const bool outlier = i < static_cast<int>(frame.outliers.size()) && frame.outliers[i];
    if (mp && !outlier && (!map_only || mp->NumObservations() > 0)) ++n;
  }
  return n;
}

void AddVisualOdometryPoints(double th_depth, int min_points, Frame* last) {
  std::vector<std::pair<float, int>> by_depth;
  for (int i = 0; i < last->size(); ++i) {
    if (!last->HasDepth(i)) continue;
    const auto& mp = last->map_points[i];
    if (mp && mp->NumObservations() > 0) continue;
    by_depth.emplace_back(last->depth()[i], i);
  }
  std::sort(by_depth.begin(), by_depth.end());
  int added = 0;
  for (const auto& [depth, i] : by_depth) {
    if (depth > th_depth && added >= min_points) break;
    const auto world = last->UnprojectStereo(i);
    if (!world) continue;
    last->map_points[i] = MapPoint::Temporary(*world, last->descriptors()[i]);
    if (i < static_cast<int>(last->outliers.size())) last->outliers[i] = 0;
    ++added;
  }
}

bool LocalisationTracking::Track(const LocalisationFrame& frame, const LocalisationMoves& moves,
                                 Frame* current) {
  if (!frame.last_tracked) {
    // No pose to go on from: only the map can say where the camera is.
    visual_odometry_ = false;
    return moves.relocalise() && moves.local_map();
  }
  if (visual_odometry_) {
    // Visual odometry from the last frame, and a relocalisation attempt; the map wins.
    const bool motion = frame.has_velocity && moves.motion_model() &&
                        InlierMatches(*current, /*map_only=*/false) >= kMinOdometryMatches;
    std::optional<PoseAndMatches> odometry;
    if (motion) odometry = PoseAndMatches::Of(*current);
    if (moves.relocalise() && moves.local_map()) {
      visual_odometry_ = false;
      return true;
    }
    if (odometry) {
      odometry->RestoreTo(current);
      if (InlierMatches(*current, /*map_only=*/true) >= kMinMapMatches && moves.local_map()) {
        visual_odometry_ = false;  // back in the map
        return true;
      }
      odometry->RestoreTo(current);
      visual_odometry_ = true;
      return true;
    }
    visual_odometry_ = false;
    return false;
  }
  bool ok = false;
  if (frame.has_velocity && frame.after_relocalisation_gap) ok = moves.motion_model();
  if (!ok) ok = moves.reference_keyframe();
  if (ok) {
    // The map may be running out of view: then go on by visual odometry if the frame-to-frame
    // pose holds (stereo / RGB-D).
    std::optional<PoseAndMatches> before_local_map;
    if (frame.odometry_possible && frame.has_velocity &&
        InlierMatches(*current, /*map_only=*/false) >= kMinOdometryMatches) {
      before_local_map = PoseAndMatches::Of(*current);
    }
    if (moves.local_map()) return true;
    if (before_local_map) {
      before_local_map->RestoreTo(current);
      visual_odometry_ = true;
      return true;
    }
  }
  return false;
}

}  // namespace pkslam
