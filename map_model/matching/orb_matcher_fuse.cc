// OrbMatcher: fusion of map points into a keyframe (local mapping and loop closing) and the
// Sim3-guided search between two keyframes (loop closing).
#include <algorithm>
#include <cstdint>

#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"
#include "map_model/matching/orb_matcher_internal.h"

namespace pkslam {

using matching_detail::HasRight;
using matching_detail::kNoDistance;
using matching_detail::PinholeView;

namespace {

// ORB-SLAM's chi-square gates (95%) for a 2-D (mono) and 3-D (stereo) reprojection error.
constexpr double kChi2Mono = 5.99;
constexpr double kChi2Stereo = 7.8;

struct FuseCandidate {
  int index = -1;  // keypoint index in the keyframe, -1 if none
  int distance = kNoDistance;
};

// The keyframe keypoint a point projects onto, by the gates shared by both Fuse flavours:
// in front of the camera, inside the image, inside the point's scale-invariance distance range,
// seen within 60 degrees of its mean viewing direction, on the predicted level (or one below);
// with_reprojection_gate additionally requires a chi-square-consistent reprojection error
// (stereo keypoints include the right coordinate). Returns the best descriptor match.
FuseCandidate FindFuseCandidate(const KeyFrame& keyframe, const PinholeView& view,
                                const MapPoint& point, double th, bool with_reprojection_gate) {
  FuseCandidate out;
  const CameraRig& rig = keyframe.rig();
  const Eigen::Vector3d pc = view.ToCamera(point.position());
  if (pc.z() <= 0) return out;
  const double u = view.U(pc);
  const double v = view.V(pc);
  if (!rig.bounds.Contains(u, v)) return out;
  const Eigen::Vector3d ray = point.position() - view.center;
  const double distance = ray.norm();
  if (distance < point.min_distance() || distance > point.max_distance()) return out;
  if (ray.dot(point.normal()) < 0.5 * distance) return out;
  const ScalePyramid& pyramid = rig.pyramid;
  const int level = point.PredictScale(distance, pyramid);
  const double radius = th * pyramid.scale[level];
  const std::vector<int> candidates = keyframe.FeaturesInArea(u, v, radius, level - 1, level);
  const double u_right = u - view.bf / pc.z();
  const auto& keypoints = keyframe.keypoints_undistorted();
  const auto& right_u = keyframe.right_u();
  const auto& descriptors = keyframe.descriptors();
  const Descriptor& descriptor = point.descriptor();
  for (const int idx : candidates) {
    const cv::KeyPoint& kp = keypoints[idx];
    if (with_reprojection_gate) {
      const double ex = u - kp.pt.x;
      const double ey = v - kp.pt.y;
      double e2 = ex * ex + ey * ey;
      double gate = kChi2Mono;
      if (HasRight(right_u, idx)) {
        const double er = u_right - right_u[idx];
        e2 += er * er;
        gate = kChi2Stereo;
      }
      if (e2 * pyramid.inv_sigma2[kp.octave] > gate) continue;
    }
    const int d = HammingDistance(descriptor, descriptors[idx]);
    if (d < out.distance) {
      out.distance = d;
      out.index = idx;
    }
  }
  return out;
}

}  // namespace

int OrbMatcher::Fuse(const MapWriteLock& lock, KeyFrame* keyframe,
                     const std::vector<MapPointPtr>& points, double th) const {
  RequireWriteLock(lock, "OrbMatcher::Fuse");
  PKSLAM_CHECK(keyframe != nullptr, "null keyframe");
  const PinholeView view(keyframe->camera_from_world(), keyframe->rig());
  int fused = 0;
  for (const MapPointPtr& point : points) {
    // Points can turn bad inside this loop (replaced by an earlier fusion).
    if (!point || point->IsBad() || point->IsInKeyFrame(keyframe)) continue;
    const FuseCandidate c = FindFuseCandidate(*keyframe, view, *point, th, true);
    if (c.index < 0 || c.distance > kOrbThLow) continue;
    const MapPointPtr in_keyframe = keyframe->map_point(c.index);
    if (in_keyframe) {
      if (!in_keyframe->IsBad()) {
        // The better-observed point survives and inherits the other's observations.
        if (in_keyframe->NumObservations() > point->NumObservations()) {
          point->Replace(lock, in_keyframe);
        } else {
          in_keyframe->Replace(lock, point);
        }
      }
    } else {
      point->AddObservation(lock, keyframe, c.index);
      keyframe->AddMapPoint(lock, point, c.index);
    }
    ++fused;
  }
  return fused;
}

int OrbMatcher::Fuse(const MapWriteLock& lock, KeyFrame* keyframe, const Sim3d& camera_from_world,
                     const std::vector<MapPointPtr>& points, double th,
                     std::vector<MapPointPtr>* replace_with) const {
  RequireWriteLock(lock, "OrbMatcher::Fuse");
  PKSLAM_CHECK(keyframe != nullptr && replace_with != nullptr, "null argument");
  if (replace_with->size() != points.size()) replace_with->assign(points.size(), nullptr);
  const PinholeView view(camera_from_world, keyframe->rig());
  std::vector<const MapPoint*> in_keyframe_points;
  for (const auto& p : keyframe->map_points()) {
    if (p) in_keyframe_points.push_back(p.get());
  }
  std::sort(in_keyframe_points.begin(), in_keyframe_points.end());
  int fused = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const MapPointPtr& point = points[i];
    if (!point || point->IsBad()) continue;
    if (std::binary_search(in_keyframe_points.begin(), in_keyframe_points.end(), point.get())) {
      continue;
    }
    const FuseCandidate c = FindFuseCandidate(*keyframe, view, *point, th, false);
    if (c.index < 0 || c.distance > kOrbThLow) continue;
    const MapPointPtr in_keyframe = keyframe->map_point(c.index);
    if (in_keyframe) {
      if (!in_keyframe->IsBad()) (*replace_with)[i] = in_keyframe;
    } else {
      point->AddObservation(lock, keyframe, c.index);
      keyframe->AddMapPoint(lock, point, c.index);
    }
    ++fused;
  }
  return fused;
}

namespace {

// For each good point of `from` not flagged in `skip`, the keypoint of `to` it projects onto
// (best descriptor within th * predicted scale, predicted level or one below, distance
// <= TH_HIGH) through to_from_from: p_to = to_from_from * (the point in from's camera).
// Unlike ORB-SLAM, the distance-range test measures the distance in the units of the point's
// own map (|p_to| / scale): the same when the Sim3 scale is near 1, right when it is not.
std::vector<int> ProjectAndMatch(const KeyFrame& from, const KeyFrame& to,
                                 const Sim3d& to_from_from, const std::vector<std::uint8_t>& skip,
                                 double th) {
  std::vector<int> match(static_cast<std::size_t>(from.size()), -1);
  const SE3d& from_camera_from_world = from.camera_from_world();
  const CameraRig& rig = to.rig();
  const ScalePyramid& pyramid = rig.pyramid;
  const auto& points = from.map_points();
  const auto& descriptors = to.descriptors();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const MapPointPtr& point = points[i];
    if (!point || skip[i] || point->IsBad()) continue;
    const Eigen::Vector3d p_to = to_from_from * (from_camera_from_world * point->position());
    if (p_to.z() <= 0) continue;
    const double u = rig.fx * p_to.x() / p_to.z() + rig.cx;
    const double v = rig.fy * p_to.y() / p_to.z() + rig.cy;
    if (!rig.bounds.Contains(u, v)) continue;
    // The point's distance range is in its own map's units: scale the distance back.
    const double distance = p_to.norm() / to_from_from.scale();
    if (distance < point->min_distance() || distance > point->max_distance()) continue;
    const int level = point->PredictScale(distance, pyramid);
    const double radius = th * pyramid.scale[level];
    const std::vector<int> candidates = to.FeaturesInArea(u, v, radius, level - 1, level);
    const Descriptor& descriptor = point->descriptor();
    int best = kNoDistance;
    int best_index = -1;
    for (const int idx : candidates) {
      const int d = HammingDistance(descriptor, descriptors[idx]);
      if (d < best) {
        best = d;
        best_index = idx;
      }
    }
    if (best <= kOrbThHigh) match[i] = best_index;
  }
  return match;
}

}  // namespace

int OrbMatcher::SearchBySim3(const KeyFrame& kf1, const KeyFrame& kf2,
                             std::vector<MapPointPtr>* matches12, const Sim3d& s12,
                             double th) const {
  PKSLAM_CHECK(matches12 != nullptr, "null output");
  const std::size_t n1 = static_cast<std::size_t>(kf1.size());
  const std::size_t n2 = static_cast<std::size_t>(kf2.size());
  if (matches12->empty()) matches12->assign(n1, nullptr);
  PKSLAM_CHECK(matches12->size() == n1, "{} match slots for keyframe {} with {} keypoints",
               matches12->size(), kf1.id(), n1);
  // Pairs already known are not searched again, from either side.
  std::vector<std::uint8_t> known1(n1, 0);
  std::vector<std::uint8_t> known2(n2, 0);
  for (std::size_t i1 = 0; i1 < n1; ++i1) {
    const MapPointPtr& point = (*matches12)[i1];
    if (!point) continue;
    known1[i1] = 1;
    const int i2 = point->IndexInKeyFrame(&kf2);
    if (i2 >= 0 && static_cast<std::size_t>(i2) < n2) known2[i2] = 1;
  }
  const std::vector<int> match1 = ProjectAndMatch(kf1, kf2, s12.Inverse(), known1, th);
  const std::vector<int> match2 = ProjectAndMatch(kf2, kf1, s12, known2, th);
  // Keep only pairs found in both directions.
  int found = 0;
  const auto& points2 = kf2.map_points();
  for (std::size_t i1 = 0; i1 < n1; ++i1) {
    const int i2 = match1[i1];
    if (i2 < 0 || match2[i2] != static_cast<int>(i1)) continue;
    (*matches12)[i1] = points2[i2];
    ++found;
  }
  return found;
}

}  // namespace pkslam
