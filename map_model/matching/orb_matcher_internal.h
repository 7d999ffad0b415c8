// Helpers shared by the OrbMatcher translation units (not part of the public API): the
// rotation-consistency histogram, best/second-best bookkeeping, and a rigid pose prepared for
// fast projection of many points.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/bow/bow_vector.h"
#include "core/geometry/se3.h"
#include "core/geometry/sim3.h"
#include "core/sensor/camera_rig.h"
#include "map_model/matching/orb_matcher.h"

namespace pkslam::matching_detail {

// Larger than any 256-bit Hamming distance.
inline constexpr int kNoDistance = 257;

// Bin of the orientation change between two keypoints (degrees, either sign): the difference
// is wrapped to [0, 360) and rounded to one of kRotationHistogramBins bins of 12 degrees, the
// bin centred on 0 (and 360) being bin 0.
inline int RotationBin(float angle1, float angle2) {
  double rot = static_cast<double>(angle1) - static_cast<double>(angle2);
  rot = std::fmod(rot, 360.0);
  if (rot < 0) rot += 360.0;
  const int bin = static_cast<int>(std::lround(rot * kRotationHistogramBins / 360.0));
  return bin % kRotationHistogramBins;
}

// Collects match ids by orientation change; afterwards, the ids outside the three dominant
// bins (ORB-SLAM's ComputeThreeMaxima) are the rotation-inconsistent matches.
class RotationHistogram {
 public:
  RotationHistogram() : bins_(kRotationHistogramBins) {}

  void Add(float angle1, float angle2, int id) { bins_[RotationBin(angle1, angle2)].push_back(id); }

  // Calls reject(id) for every id outside the dominant bins.
  template <typename Reject>
  void RejectInconsistent(Reject&& reject) const {
    const std::array<int, 3> keep = OrbMatcher::ThreeMaxima(bins_);
    for (int b = 0; b < kRotationHistogramBins; ++b) {
      if (b == keep[0] || b == keep[1] || b == keep[2]) continue;
      for (const int id : bins_[b]) reject(id);
    }
  }

  const std::vector<std::vector<int>>& bins() const { return bins_; }

 private:
  std::vector<std::vector<int>> bins_;
};

// Best and second-best distance among candidates, with the pyramid levels of both (the
// local-map search accepts an ambiguous best when the runner-up lies on another level).
struct BestTwo {
  int best = kNoDistance;
  int second = kNoDistance;
  int best_index = -1;
  int best_level = -1;
  int second_level = -1;

  void Add(int distance, int index, int level) {
    if (distance < best) {
      second = best;
      second_level = best_level;
      best = distance;
      best_index = index;
      best_level = level;
    } else if (distance < second) {
      second = distance;
      second_level = level;
    }
  }
};

// A camera_from_world pose as a rotation matrix + translation, with the camera centre, and
// the pinhole intrinsics of the rig: the per-point work of every projection search.
struct PinholeView {
  Eigen::Matrix3d rotation;     // camera_from_world rotation
  Eigen::Vector3d translation;  // camera_from_world translation
  Eigen::Vector3d center;       // camera centre in world
  double fx, fy, cx, cy, bf;

  PinholeView(const SE3d& camera_from_world, const CameraRig& rig)
      : rotation(camera_from_world.RotationMatrix()),
        translation(camera_from_world.translation()),
        center(-(rotation.transpose() * translation)),
        fx(rig.fx),
        fy(rig.fy),
        cx(rig.cx),
        cy(rig.cy),
        bf(rig.bf) {}

  // A Sim3 camera_from_world used as a rigid pose: the scale only scales depths, so the
  // camera frame is taken as R * p + t / s (ORB-SLAM's loop searches do the same).
  PinholeView(const Sim3d& camera_from_world, const CameraRig& rig)
      : PinholeView(SE3d(camera_from_world.so3(),
                         camera_from_world.translation() / camera_from_world.scale()),
                    rig) {}

  Eigen::Vector3d ToCamera(const Eigen::Vector3d& p_world) const {
    return rotation * p_world + translation;
  }
  double U(const Eigen::Vector3d& p_camera) const { return fx * p_camera.x() / p_camera.z() + cx; }
  double V(const Eigen::Vector3d& p_camera) const { return fy * p_camera.y() / p_camera.z() + cy; }
};

// Calls f(features_a, features_b) for every vocabulary node present in both feature vectors,
// in increasing node order (a merge that skips ahead with binary search).
template <typename F>
void ForEachCommonNode(const FeatureVector& a, const FeatureVector& b, F&& f) {
  const auto node_less = [](const FeatureGroup& g, NodeId id) { return g.node_id < id; };
  auto ia = a.begin();
  auto ib = b.begin();
  while (ia != a.end() && ib != b.end()) {
    if (ia->node_id == ib->node_id) {
      f(ia->features, ib->features);
      ++ia;
      ++ib;
    } else if (ia->node_id < ib->node_id) {
      ia = std::lower_bound(ia, a.end(), ib->node_id, node_less);
    } else {
      ib = std::lower_bound(ib, b.end(), ia->node_id, node_less);
    }
  }
}

// True if keypoint i has a stereo / RGB-D right coordinate.
inline bool HasRight(const std::vector<float>& right_u, int i) {
  return !right_u.empty() && right_u[static_cast<std::size_t>(i)] >= 0;
}

}  // namespace pkslam::matching_detail
