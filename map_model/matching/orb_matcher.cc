// OrbMatcher: the rotation histogram maxima and the four search-by-projection flavours
// (local map, motion model, relocalisation, Sim3 loop). The BoW / epipolar / window searches
// are in orb_matcher_bow.cc, fusion and the Sim3 search in orb_matcher_fuse.cc.
#include "map_model/matching/orb_matcher.h"

#include <algorithm>
#include <cstdint>

#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher_internal.h"

namespace pkslam {

using matching_detail::BestTwo;
using matching_detail::HasRight;
using matching_detail::kNoDistance;
using matching_detail::PinholeView;
using matching_detail::RotationHistogram;

std::array<int, 3> OrbMatcher::ThreeMaxima(const std::vector<std::vector<int>>& histogram) {
  std::array<std::size_t, 3> max{0, 0, 0};
  std::array<int, 3> index{-1, -1, -1};
  for (std::size_t i = 0; i < histogram.size(); ++i) {
    const std::size_t s = histogram[i].size();
    const int bin = static_cast<int>(i);
    if (s > max[0]) {
      max = {s, max[0], max[1]};
      index = {bin, index[0], index[1]};
    } else if (s > max[1]) {
      max = {max[0], s, max[1]};
      index = {index[0], bin, index[1]};
    } else if (s > max[2]) {
      max[2] = s;
      index[2] = bin;
    }
  }
  // Secondary peaks count only when they hold at least 10% of the main one.
  const double floor = 0.1 * static_cast<double>(max[0]);
  if (static_cast<double>(max[1]) < floor) {
    index[1] = -1;
    index[2] = -1;
  } else if (static_cast<double>(max[2]) < floor) {
    index[2] = -1;
  }
  return index;
}

int OrbMatcher::SearchByProjection(Frame* frame, const std::vector<ProjectedPoint>& points,
                                   double th, double far_points_th) const {
  PKSLAM_CHECK(frame != nullptr, "null frame");
  const auto& keypoints = frame->keypoints_undistorted();
  const auto& descriptors = frame->descriptors();
  const auto& right_u = frame->right_u();
  const auto& scale = frame->rig().pyramid.scale;
  const int n_levels = frame->rig().pyramid.n_levels;
  auto& slots = frame->map_points;
  PKSLAM_CHECK(static_cast<int>(slots.size()) == frame->size(), "frame {}: {} slots, {} keypoints",
               frame->id(), slots.size(), frame->size());
  // Slots filled by this call: a later point must not steal them (the previous content may
  // be a point without observations, which matching is allowed to overwrite).
  std::vector<std::uint8_t> claimed(slots.size(), 0);
  std::vector<int> candidates;
  candidates.reserve(64);
  int matches = 0;
  for (const ProjectedPoint& p : points) {
    if (!p.point || p.point->IsBad()) continue;
    if (far_points_th > 0 && p.depth > far_points_th) continue;
    const int level = std::clamp(p.predicted_level, 0, n_levels - 1);
    const double radius = RadiusByViewingCos(p.view_cos) * th * scale[level];
    frame->FeaturesInArea(p.u, p.v, radius, level - 1, level, &candidates);
    if (candidates.empty()) continue;
    const Descriptor& descriptor = p.point->descriptor();
    BestTwo best;
    for (const int idx : candidates) {
      if (claimed[idx]) continue;
      if (slots[idx] && slots[idx]->NumObservations() > 0) continue;
      if (p.u_right >= 0 && HasRight(right_u, idx) && std::abs(p.u_right - right_u[idx]) > radius) {
        continue;
      }
      best.Add(HammingDistance(descriptor, descriptors[idx]), idx, keypoints[idx].octave);
    }
    if (best.best > kOrbThHigh) continue;
    // Ambiguous on the same level: reject. A runner-up on another level is the same
    // structure seen at another scale, not a competitor.
    if (best.best_level == best.second_level && best.best > nn_ratio_ * best.second) continue;
    slots[best.best_index] = p.point;
    claimed[best.best_index] = 1;
    ++matches;
  }
  return matches;
}

int OrbMatcher::SearchByProjection(Frame* current, const Frame& last_frame, double th,
                                   bool monocular) const {
  PKSLAM_CHECK(current != nullptr, "null frame");
  PKSLAM_CHECK(current->HasPose() && last_frame.HasPose(), "frames {} and {} need poses",
               current->id(), last_frame.id());
  const CameraRig& rig = current->rig();
  const PinholeView view(current->camera_from_world(), rig);
  // The current camera centre seen from the last camera: moving forward by more than a
  // baseline makes points grow (coarser octaves), moving backward makes them shrink.
  const Eigen::Vector3d center_in_last = last_frame.camera_from_world() * view.center;
  const bool forward = !monocular && center_in_last.z() > rig.baseline;
  const bool backward = !monocular && -center_in_last.z() > rig.baseline;

  const auto& keypoints = current->keypoints_undistorted();
  const auto& last_keypoints = last_frame.keypoints_undistorted();
  const auto& descriptors = current->descriptors();
  const auto& right_u = current->right_u();
  const auto& scale = rig.pyramid.scale;
  auto& slots = current->map_points;
  PKSLAM_CHECK(static_cast<int>(slots.size()) == current->size(),
               "frame {}: {} slots, {} keypoints", current->id(), slots.size(), current->size());
  std::vector<std::uint8_t> claimed(slots.size(), 0);
  std::vector<int> candidates;
  candidates.reserve(64);
  RotationHistogram histogram;
  int matches = 0;
  for (std::size_t i = 0; i < last_frame.map_points.size(); ++i) {
    const MapPointPtr& point = last_frame.map_points[i];
    const bool outlier = i < last_frame.outliers.size() && last_frame.outliers[i];
    if (!point || outlier || point->IsBad()) continue;
    const Eigen::Vector3d pc = view.ToCamera(point->position());
    if (pc.z() <= 0) continue;
    const double u = view.U(pc);
    const double v = view.V(pc);
    if (!rig.bounds.Contains(u, v)) continue;
    const int last_octave = last_keypoints[i].octave;
    const double radius = th * scale[last_octave];
    if (forward) {
      current->FeaturesInArea(u, v, radius, last_octave, -1, &candidates);
    } else if (backward) {
      current->FeaturesInArea(u, v, radius, 0, last_octave, &candidates);
    } else {
      current->FeaturesInArea(u, v, radius, last_octave - 1, last_octave + 1, &candidates);
    }
    if (candidates.empty()) continue;
    const double u_right = u - view.bf / pc.z();
    const Descriptor& descriptor = point->descriptor();
    int best = kNoDistance;
    int best_index = -1;
    for (const int idx : candidates) {
      if (claimed[idx]) continue;
      if (slots[idx] && slots[idx]->NumObservations() > 0) continue;
      if (HasRight(right_u, idx) && std::abs(u_right - right_u[idx]) > radius) continue;
      const int d = HammingDistance(descriptor, descriptors[idx]);
      if (d < best) {
        best = d;
        best_index = idx;
      }
    }
    if (best > kOrbThHigh) continue;
    slots[best_index] = point;
    claimed[best_index] = 1;
    ++matches;
    if (check_orientation_) {
      histogram.Add(last_keypoints[i].angle, keypoints[best_index].angle, best_index);
    }
  }
  if (check_orientation_) {
    histogram.RejectInconsistent([&](int idx) {
      slots[idx] = nullptr;
      --matches;
    });
  }
  return matches;
}

int OrbMatcher::SearchByProjection(Frame* current, const KeyFrame& keyframe,
                                   const std::vector<MapPoint*>& already_found, double th,
                                   int orb_distance) const {
  PKSLAM_CHECK(current != nullptr, "null frame");
  PKSLAM_CHECK(current->HasPose(), "frame {} needs a pose", current->id());
  const CameraRig& rig = current->rig();
  const PinholeView view(current->camera_from_world(), rig);
  std::vector<const MapPoint*> found(already_found.begin(), already_found.end());
  std::sort(found.begin(), found.end());

  const auto& keypoints = current->keypoints_undistorted();
  const auto& kf_keypoints = keyframe.keypoints_undistorted();
  const auto& descriptors = current->descriptors();
  const ScalePyramid& pyramid = rig.pyramid;
  auto& slots = current->map_points;
  PKSLAM_CHECK(static_cast<int>(slots.size()) == current->size(),
               "frame {}: {} slots, {} keypoints", current->id(), slots.size(), current->size());
  RotationHistogram histogram;
  int matches = 0;
  const auto& kf_points = keyframe.map_points();
  for (std::size_t i = 0; i < kf_points.size(); ++i) {
    const MapPointPtr& point = kf_points[i];
    if (!point || point->IsBad()) continue;
    if (std::binary_search(found.begin(), found.end(), point.get())) continue;
    const Eigen::Vector3d pc = view.ToCamera(point->position());
    if (pc.z() <= 0) continue;
    const double u = view.U(pc);
    const double v = view.V(pc);
    if (!rig.bounds.Contains(u, v)) continue;
    const double distance = (point->position() - view.center).norm();
    if (distance < point->min_distance() || distance > point->max_distance()) continue;
    const int level = point->PredictScale(distance, pyramid);
    const double radius = th * pyramid.scale[level];
    const std::vector<int> candidates = current->FeaturesInArea(u, v, radius, level - 1, level + 1);
    const Descriptor& descriptor = point->descriptor();
    int best = kNoDistance;
    int best_index = -1;
    for (const int idx : candidates) {
      if (slots[idx]) continue;
      const int d = HammingDistance(descriptor, descriptors[idx]);
      if (d < best) {
        best = d;
        best_index = idx;
      }
    }
    if (best > orb_distance) continue;
    slots[best_index] = point;
    ++matches;
    if (check_orientation_) {
      histogram.Add(kf_keypoints[i].angle, keypoints[best_index].angle, best_index);
    }
  }
  if (check_orientation_) {
    histogram.RejectInconsistent([&](int idx) {
      slots[idx] = nullptr;
      --matches;
    });
  }
  return matches;
}

int OrbMatcher::SearchByProjection(const KeyFrame& keyframe, const Sim3d& camera_from_world,
                                   const std::vector<MapPointPtr>& points,
                                   std::vector<MapPointPtr>* matched, double th,
                                   double ratio_hamming) const {
  PKSLAM_CHECK(matched != nullptr, "null output");
  const std::size_t n = static_cast<std::size_t>(keyframe.size());
  if (matched->empty()) matched->assign(n, nullptr);
  PKSLAM_CHECK(matched->size() == n, "{} match slots for keyframe {} with {} keypoints",
               matched->size(), keyframe.id(), n);
  const CameraRig& rig = keyframe.rig();
  const PinholeView view(camera_from_world, rig);
  std::vector<const MapPoint*> found;
  for (const auto& p : *matched) {
    if (p) found.push_back(p.get());
  }
  std::sort(found.begin(), found.end());

  const auto& descriptors = keyframe.descriptors();
  const ScalePyramid& pyramid = rig.pyramid;
  const double max_distance = kOrbThLow * ratio_hamming;
  int matches = 0;
  for (const MapPointPtr& point : points) {
    if (!point || point->IsBad()) continue;
    if (std::binary_search(found.begin(), found.end(), point.get())) continue;
    const Eigen::Vector3d pc = view.ToCamera(point->position());
    if (pc.z() <= 0) continue;
    const double u = view.U(pc);
    const double v = view.V(pc);
    if (!rig.bounds.Contains(u, v)) continue;
    const Eigen::Vector3d ray = point->position() - view.center;
    const double distance = ray.norm();
    if (distance < point->min_distance() || distance > point->max_distance()) continue;
    // Viewing angle within 60 degrees of the point's mean viewing direction.
    if (ray.dot(point->normal()) < 0.5 * distance) continue;
    const int level = point->PredictScale(distance, pyramid);
    const double radius = th * pyramid.scale[level];
    const std::vector<int> candidates = keyframe.FeaturesInArea(u, v, radius, level - 1, level);
    const Descriptor& descriptor = point->descriptor();
    int best = kNoDistance;
    int best_index = -1;
    for (const int idx : candidates) {
      if ((*matched)[idx]) continue;
      const int d = HammingDistance(descriptor, descriptors[idx]);
      if (d < best) {
        best = d;
        best_index = idx;
      }
    }
    if (best > max_distance) continue;
    (*matched)[best_index] = point;
    ++matches;
  }
  return matches;
}

}  // namespace pkslam
