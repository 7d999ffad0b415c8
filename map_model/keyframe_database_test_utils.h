// Test/benchmark helpers for the keyframe database: keyframes with BoW vectors over a
// synthetic scene (from the shared synthetic-map fixture).
#pragma once

#include <memory>
#include <mutex>
#include <vector>

#include "core/bow/vocabulary.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam::testing {

// Keyframes (with BoW) at `poses` in `map`, with map points for the scene points that at least
// two of them see. Points are shared only among the keyframes of one call, so two calls over
// the same place make two unconnected keyframe groups (a revisit before loop closure).
inline std::vector<KeyFramePtr> AddKeyFrames(Atlas* atlas, Map* map, const SyntheticScene& scene,
                                             const std::shared_ptr<const CameraRig>& rig,
                                             const std::vector<SE3d>& poses,
                                             const Vocabulary& vocabulary, std::uint64_t seed) {
  auto lock = MapEditor(atlas).Write(MapEdit::kFixture);
  std::vector<KeyFramePtr> kfs;
  std::vector<std::vector<int>> keypoint_points;
  std::vector<int> seen(scene.points_world.size(), 0);
  for (std::size_t k = 0; k < poses.size(); ++k) {
    FrameOptions options;
    options.descriptor_bit_flips = 2;
    options.seed = seed + k;
    std::vector<int> kp_points;
    Frame f = MakeFrame(scene, rig, poses[k], atlas->NextFrameId(), 0, options, &kp_points);
    f.ComputeBoW(vocabulary);
    f.SetPose(poses[k]);
    auto kf = std::make_shared<KeyFrame>(atlas->NextKeyFrameId(), f, map);
    map->AddKeyFrame(lock, kf);
    kfs.push_back(kf);
    for (int p : kp_points) ++seen[p];
    keypoint_points.push_back(std::move(kp_points));
  }
  std::vector<MapPointPtr> points(scene.points_world.size());
  for (std::size_t k = 0; k < kfs.size(); ++k) {
    for (std::size_t i = 0; i < keypoint_points[k].size(); ++i) {
      const int p = keypoint_points[k][i];
      if (seen[p] < 2) continue;
      if (!points[p]) {
        points[p] = std::make_shared<MapPoint>(atlas->NextMapPointId(), scene.points_world[p],
                                               kfs[k].get(), map);
        map->AddMapPoint(lock, points[p]);
      }
      points[p]->AddObservation(lock, kfs[k].get(), static_cast<int>(i));
      kfs[k]->AddMapPoint(lock, points[p], static_cast<int>(i));
    }
  }
  for (const auto& kf : kfs) kf->UpdateConnections(lock);
  return kfs;
}

// Camera poses along +x (looking along +z) from x0 in steps of `step`.
inline std::vector<SE3d> Strip(double x0, double step, int n, double y = 0) {
  std::vector<SE3d> out;
  for (int i = 0; i < n; ++i) {
    out.push_back(SE3d(SO3d(), Eigen::Vector3d(x0 + step * i, y, 0)).Inverse());
  }
  return out;
}

}  // namespace pkslam::testing
