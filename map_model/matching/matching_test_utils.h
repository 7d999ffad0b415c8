// Test and benchmark helpers for map_model/matching, on top of the synthetic-map fixture: frames
// with edited features, the tracker's frustum test producing ProjectedPoints, a vocabulary
// trained on a scene, and keyframes with BoW.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <vector>

#include "core/bow/vocabulary.h"
#include "core/geometry/sim3.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam::testing {

// A copy of `frame` rebuilt from edited features (pose and map points are not copied).
inline Frame EditFrame(const Frame& frame, const std::function<void(FrameFeatures*)>& edit) {
  FrameFeatures f;
  f.keypoints = frame.keypoints();
  f.descriptors = frame.descriptors();
  f.right_u = frame.right_u();
  f.depth = frame.depth();
  edit(&f);
  return Frame(frame.id(), frame.t_ns(), frame.rig_ptr(), std::move(f));
}

// MakeFrame with the pose set.
inline Frame MakePosedFrame(const SyntheticScene& scene,
                            const std::shared_ptr<const CameraRig>& rig,
                            const SE3d& camera_from_world, FrameId id, const FrameOptions& options,
                            std::vector<int>* point_of_keypoint) {
  Frame f =
      MakeFrame(scene, rig, camera_from_world, id, id * 50'000'000, options, point_of_keypoint);
  f.SetPose(camera_from_world);
  return f;
}

// The tracker's frustum test (ORB-SLAM's isInFrustum): points in front of the camera, inside
// the image and the point's distance range, seen within 60 degrees of their mean direction.
inline std::vector<ProjectedPoint> ProjectMapPoints(const std::vector<MapPointPtr>& points,
                                                    const Frame& frame) {
  const CameraRig& rig = frame.rig();
  const Eigen::Vector3d center = frame.CameraCenter();
  std::vector<ProjectedPoint> out;
  for (const auto& mp : points) {
    if (!mp || mp->IsBad()) continue;
    const Eigen::Vector3d pc = frame.camera_from_world() * mp->position();
    if (pc.z() <= 0) continue;
    ProjectedPoint p;
    p.point = mp;
    p.u = rig.fx * pc.x() / pc.z() + rig.cx;
    p.v = rig.fy * pc.y() / pc.z() + rig.cy;
    if (!rig.bounds.Contains(p.u, p.v)) continue;
    const Eigen::Vector3d ray = mp->position() - center;
    const double distance = ray.norm();
    if (distance < mp->min_distance() || distance > mp->max_distance()) continue;
    p.view_cos = ray.dot(mp->normal()) / distance;
    if (p.view_cos < 0.5) continue;
    p.predicted_level = mp->PredictScale(distance, rig.pyramid);
    p.u_right = p.u - rig.bf / pc.z();
    p.depth = pc.z();
    out.push_back(p);
  }
  return out;
}

// Scene whose descriptors are drawn around 16 prototypes (40 random bits flipped each), so
// that a small vocabulary groups noisy views of a point under the same node.
inline SyntheticScene MakeClusteredScene(int n, std::uint64_t seed) {
  SyntheticScene scene = MakeScene(n, seed);
  std::mt19937_64 rng(seed + 1000);
  std::uniform_int_distribution<int> bit(0, 255);
  std::vector<Descriptor> prototypes(16);
  for (auto& p : prototypes) {
    for (auto& b : p.bytes) b = static_cast<std::uint8_t>(rng());
  }
  for (std::size_t i = 0; i < scene.descriptors.size(); ++i) {
    Descriptor d = prototypes[i % prototypes.size()];
    for (int k = 0; k < 40; ++k) {
      const int b = bit(rng);
      d.bytes[b / 8] ^= static_cast<std::uint8_t>(1u << (b % 8));
    }
    scene.descriptors[i] = d;
  }
  return scene;
}

// A one-level vocabulary (k = 16) trained on the scene's descriptors. TF weighting: every
// training image holds every word, so IDF would zero them all (and drop them from the
// feature vectors).
inline Vocabulary TrainSceneVocabulary(const SyntheticScene& scene) {
  std::vector<std::vector<Descriptor>> images(8);
  for (std::size_t i = 0; i < scene.descriptors.size(); ++i) {
    images[i % images.size()].push_back(scene.descriptors[i]);
  }
  VocabularyTrainOptions options;
  options.branching = 16;
  options.levels = 1;
  options.weighting = Weighting::kTf;
  options.quiet = true;
  return Vocabulary::Train(images, options);
}

// Keyframes with BoW at the given poses. with_points: a map point per scene point seen twice
// or more, observed by every keyframe that sees it (as MakeMap); otherwise no map points.
inline SyntheticMap MakeBowMap(Atlas* atlas, const SyntheticScene& scene,
                               const std::shared_ptr<const CameraRig>& rig,
                               const std::vector<SE3d>& camera_from_world,
                               const FrameOptions& options, const Vocabulary& vocabulary,
                               bool with_points) {
  auto lock = MapEditor(atlas).Write(MapEdit::kFixture);
  Map* map = atlas->current_map();
  SyntheticMap out;
  out.point_of_scene_index.assign(scene.points_world.size(), nullptr);
  std::vector<int> seen(scene.points_world.size(), 0);
  for (std::size_t k = 0; k < camera_from_world.size(); ++k) {
    FrameOptions o = options;
    o.seed = options.seed + k;
    std::vector<int> kp_points;
    Frame f = MakePosedFrame(scene, rig, camera_from_world[k], atlas->NextFrameId(), o, &kp_points);
    f.ComputeBoW(vocabulary);
    for (int p : kp_points) ++seen[p];
    auto kf = std::make_shared<KeyFrame>(atlas->NextKeyFrameId(), f, map);
    map->AddKeyFrame(lock, kf);
    out.keyframes.push_back(kf);
    out.keypoint_points.push_back(kp_points);
  }
  if (!with_points) return out;
  for (std::size_t k = 0; k < out.keyframes.size(); ++k) {
    KeyFrame* kf = out.keyframes[k].get();
    for (std::size_t i = 0; i < out.keypoint_points[k].size(); ++i) {
      const int p = out.keypoint_points[k][i];
      if (seen[p] < 2) continue;
      MapPointPtr& mp = out.point_of_scene_index[p];
      if (!mp) {
        mp = std::make_shared<MapPoint>(atlas->NextMapPointId(), scene.points_world[p], kf, map);
        map->AddMapPoint(lock, mp);
      }
      mp->AddObservation(lock, kf, static_cast<int>(i));
      kf->AddMapPoint(lock, mp, static_cast<int>(i));
    }
  }
  for (const auto& mp : out.point_of_scene_index) {
    if (!mp) continue;
    mp->ComputeDistinctiveDescriptor(lock);
    mp->UpdateNormalAndDepth(lock);
  }
  for (const auto& kf : out.keyframes) kf->UpdateConnections(lock);
  return out;
}

// Scene index of each map point of a synthetic map.
inline std::map<const MapPoint*, int> SceneIndexOf(const SyntheticMap& map) {
  std::map<const MapPoint*, int> out;
  for (std::size_t j = 0; j < map.point_of_scene_index.size(); ++j) {
    if (map.point_of_scene_index[j]) out[map.point_of_scene_index[j].get()] = static_cast<int>(j);
  }
  return out;
}

// A similar copy of the world, p_b = s * p + offset (as the second map of a loop): the scene
// in it, and the camera poses in it (camera coordinates scaled by s).
inline SyntheticScene TransformScene(SyntheticScene scene, double s,
                                     const Eigen::Vector3d& offset) {
  for (auto& p : scene.points_world) p = s * p + offset;
  return scene;
}
inline std::vector<SE3d> TransformPoses(std::vector<SE3d> poses, double s,
                                        const Eigen::Vector3d& offset) {
  for (auto& pose : poses) {
    pose = SE3d(pose.so3(), s * pose.translation() - pose.so3() * offset);
  }
  return poses;
}
// camera_from_world (true world) as a Sim3 from the copied world: p_c = R (p_b - o) / s + t.
inline Sim3d CameraFromCopiedWorld(const SE3d& camera_from_world, double s,
                                   const Eigen::Vector3d& offset) {
  return Sim3d(1.0 / s, camera_from_world.so3(),
               camera_from_world.translation() - (camera_from_world.so3() * offset) / s);
}

// A stereo map with BoW and points (MakeBowMap) over a scene of `points` points, keyframes along
// MakeForwardPath(keyframes, 0.15 m): the fixture of the tracking parts' tests.
struct StereoBowMap {
  StereoBowMap(int points, std::uint64_t scene_seed, int keyframes, std::uint64_t path_seed)
      : scene(MakeScene(points, scene_seed)),
        vocabulary(TrainSceneVocabulary(scene)),
        rig(MakeStereoRig()),
        poses(MakeForwardPath(keyframes, 0.15, path_seed)),
        map(MakeBowMap(&atlas, scene, rig, poses, {}, vocabulary, true)) {}

  // A frame of the scene at `camera_from_world` (no pose set), id `id` at id * 50 ms, 0.5 px
  // noise drawn with `seed`; `point_of_keypoint` (optional) gets each keypoint's scene index.
  Frame NoisyFrame(const SE3d& camera_from_world, FrameId id, std::uint64_t seed,
                   std::vector<int>* point_of_keypoint = nullptr) const {
    std::vector<int> unused;
    FrameOptions options;
    options.pixel_noise = 0.5;
    options.seed = seed;
    return MakeFrame(scene, rig, camera_from_world, id, id * 50'000'000, options,
                     point_of_keypoint != nullptr ? point_of_keypoint : &unused);
  }

  SyntheticScene scene;
  Vocabulary vocabulary;
  std::shared_ptr<CameraRig> rig;
  std::vector<SE3d> poses;
  Atlas atlas;
  SyntheticMap map;
};

}  // namespace pkslam::testing
