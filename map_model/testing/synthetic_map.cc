#include "map_model/testing/synthetic_map.h"

#include <mutex>

#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"

namespace pkslam::testing {

std::shared_ptr<CameraRig> MakeStereoRig(Sensor sensor) {
  auto rig = std::make_shared<CameraRig>();
  rig->sensor = sensor;
  rig->camera = CameraModel::Pinhole(752, 480, 435.0, 435.0, 367.0, 248.0);
  rig->baseline = 0.11;
  rig->bf = 435.0 * 0.11;
  rig->th_depth = 35.0 * rig->baseline;
  rig->pyramid = ScalePyramid(8, 1.2);
  rig->UpdateDerived();
  return rig;
}

SyntheticScene MakeScene(int n, std::uint64_t seed, double w, double h, double z0, double z1) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ux(-w, w), uy(-h, h), uz(z0, z1);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<int> level(0, 3);
  SyntheticScene scene;
  for (int i = 0; i < n; ++i) {
    scene.points_world.emplace_back(ux(rng), uy(rng), uz(rng));
    Descriptor d;
    for (auto& b : d.bytes) b = static_cast<std::uint8_t>(byte(rng));
    scene.descriptors.push_back(d);
    scene.octaves.push_back(level(rng));
  }
  return scene;
}

Frame MakeFrame(const SyntheticScene& scene, const std::shared_ptr<const CameraRig>& rig,
                const SE3d& camera_from_world, FrameId id, std::int64_t t_ns,
                const FrameOptions& options, std::vector<int>* point_of_keypoint) {
  std::mt19937_64 rng(options.seed ^ static_cast<std::uint64_t>(id * 7919 + 17));
  std::normal_distribution<double> noise(0.0, options.pixel_noise);
  std::uniform_int_distribution<int> bit(0, 255);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  FrameFeatures f;
  point_of_keypoint->clear();
  for (std::size_t i = 0; i < scene.points_world.size(); ++i) {
    const Eigen::Vector3d pc = camera_from_world * scene.points_world[i];
    if (pc.z() < 0.2) continue;
    auto uv = rig->camera.Project(pc);
    if (!uv || !rig->camera.InImage(*uv, 20.0)) continue;
    Eigen::Vector2d obs = *uv;
    if (options.pixel_noise > 0) obs += Eigen::Vector2d(noise(rng), noise(rng));
    if (options.outlier_fraction > 0 && unit(rng) < options.outlier_fraction) {
      obs = Eigen::Vector2d(30 + unit(rng) * (rig->camera.width() - 60),
                            30 + unit(rng) * (rig->camera.height() - 60));
    }
    cv::KeyPoint kp(static_cast<float>(obs.x()), static_cast<float>(obs.y()),
                    static_cast<float>(31 * rig->pyramid.scale[scene.octaves[i]]), 0.0f, 1.0f,
                    scene.octaves[i]);
    kp.angle = 45.0f;
    Descriptor d = scene.descriptors[i];
    for (int k = 0; k < options.descriptor_bit_flips; ++k) {
      const int b = bit(rng);
      d.bytes[b / 8] ^= static_cast<std::uint8_t>(1u << (b % 8));
    }
    f.keypoints.push_back(kp);
    f.descriptors.push_back(d);
    if (options.stereo) {
      const double depth = pc.z();
      f.depth.push_back(static_cast<float>(depth));
      f.right_u.push_back(static_cast<float>(obs.x() - rig->bf / depth));
    }
    point_of_keypoint->push_back(static_cast<int>(i));
  }
  return Frame(id, t_ns, rig, std::move(f));
}

SyntheticMap MakeMap(Atlas* atlas, const SyntheticScene& scene,
                     const std::shared_ptr<const CameraRig>& rig,
                     const std::vector<SE3d>& camera_from_world, const FrameOptions& options) {
  auto lock = MapEditor(atlas).Write(MapEdit::kFixture);
  Map* map = atlas->current_map();
  SyntheticMap out;
  out.point_of_scene_index.assign(scene.points_world.size(), nullptr);
  std::vector<int> seen_count(scene.points_world.size(), 0);
  std::vector<Frame> frames;
  for (std::size_t k = 0; k < camera_from_world.size(); ++k) {
    std::vector<int> kp_points;
    FrameOptions o = options;
    o.seed = options.seed + k;
    Frame f = MakeFrame(scene, rig, camera_from_world[k], atlas->NextFrameId(),
                        static_cast<std::int64_t>(k) * 50'000'000, o, &kp_points);
    f.SetPose(camera_from_world[k]);
    for (int p : kp_points) ++seen_count[p];
    out.keypoint_points.push_back(kp_points);
    frames.push_back(std::move(f));
  }
  for (std::size_t k = 0; k < frames.size(); ++k) {
    auto kf = std::make_shared<KeyFrame>(atlas->NextKeyFrameId(), frames[k], map);
    map->AddKeyFrame(lock, kf);
    out.keyframes.push_back(kf);
  }
  for (std::size_t k = 0; k < frames.size(); ++k) {
    KeyFrame* kf = out.keyframes[k].get();
    const auto& kp_points = out.keypoint_points[k];
    for (std::size_t i = 0; i < kp_points.size(); ++i) {
      const int p = kp_points[i];
      if (seen_count[p] < 2) continue;
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

std::vector<SE3d> MakeForwardPath(int n, double step, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> wobble(0.0, 0.01);
  std::vector<SE3d> out;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d angles = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    const SE3d world_from_camera(SO3d::Exp(angles), position);
    out.push_back(world_from_camera.Inverse());
    position += Eigen::Vector3d(step, 0.2 * step, 0.3 * step) +
                Eigen::Vector3d(wobble(rng), wobble(rng), wobble(rng)) * step;
    angles += Eigen::Vector3d(wobble(rng), wobble(rng), wobble(rng));
  }
  return out;
}

}  // namespace pkslam::testing
