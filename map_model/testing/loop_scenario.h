// Test/benchmark scenario for the essential graph: a camera on a circle looking out at a
// cylindrical wall makes one lap and a bit; its map is built from the synthetic-map fixture
// with true poses, then drifted (each keyframe by an accumulated Sim3 drift, each point with
// its reference keyframe), the links across the loop are cut (before loop closure the two
// sides share no covisibility), and the loop is "detected" between the last keyframe and the
// keyframe of the first lap that sees the same wall: the neighbourhood of the last keyframe is
// corrected exactly as ORB-SLAM's CorrectLoop would with a perfect loop Sim3, and the links
// across the loop come back as new loop connections.
#pragma once

#include <cmath>
#include <mutex>
#include <set>
#include <vector>

#include "map_model/estimation/essential_graph_collect.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam::testing {

struct LoopScenarioOptions {
  int keyframes_per_lap = 36;
  int extra_keyframes = 4;  // beyond the lap: these revisit the first ones
  int num_points = 3000;
  double drift_scale_per_keyframe = 1.004;  // 1 for stereo-like (SE3) drift
  double drift_yaw_per_keyframe = 0.004;    // rad
  // m. A constant bias of the step in the camera frame sums to ~0 around a circle, so a loop
  // cannot observe it (it bends the circle): keep it small to test what a loop can fix.
  double drift_step_per_keyframe = 0.002;
  std::uint64_t seed = 3;
  // The scenario's world in the map's world (identity: the circle's axis, the drift's rotation
  // axis, is y; a rotation taking y to z makes it a gravity-aligned inertial world). Rotate
  // the scene with RotateScene to match.
  SO3d world_from_scenario;
};

struct LoopScenario {
  Atlas atlas;
  Map* map = nullptr;
  SyntheticMap synthetic;
  std::vector<SE3d> true_camera_from_world;
  LoopCorrection correction;
};

// Camera centre error (m, RMS over live keyframes) of the map against the truth.
inline double KeyFramePositionRmse(const LoopScenario& s) {
  double sum = 0;
  int n = 0;
  for (std::size_t k = 0; k < s.synthetic.keyframes.size(); ++k) {
    const auto& kf = s.synthetic.keyframes[k];
    if (kf->IsBad()) continue;
    sum += (kf->CameraCenter() - s.true_camera_from_world[k].Inverse().translation()).squaredNorm();
    ++n;
  }
  return std::sqrt(sum / std::max(n, 1));
}

// Map point error (m, RMS) against the scene.
inline double PointRmse(const LoopScenario& s, const SyntheticScene& scene) {
  double sum = 0;
  int n = 0;
  for (std::size_t p = 0; p < scene.points_world.size(); ++p) {
    const auto& mp = s.synthetic.point_of_scene_index[p];
    if (!mp || mp->IsBad()) continue;
    sum += (mp->position() - scene.points_world[p]).squaredNorm();
    ++n;
  }
  return std::sqrt(sum / std::max(n, 1));
}

inline SyntheticScene MakeCylinderScene(int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> angle(0.0, 2 * M_PI), height(-2.0, 2.0);
  std::uniform_int_distribution<int> byte(0, 255), level(0, 3);
  SyntheticScene scene;
  for (int i = 0; i < n; ++i) {
    const double a = angle(rng);
    scene.points_world.emplace_back(8.0 * std::cos(a), height(rng), 8.0 * std::sin(a));
    Descriptor d;
    for (auto& b : d.bytes) b = static_cast<std::uint8_t>(byte(rng));
    scene.descriptors.push_back(d);
    scene.octaves.push_back(level(rng));
  }
  return scene;
}

inline void RotateScene(const SO3d& world_from_scenario, SyntheticScene* scene) {
  for (auto& p : scene->points_world) p = world_from_scenario * p;
}

inline void BuildLoopScenario(const LoopScenarioOptions& o, const SyntheticScene& scene,
                              LoopScenario* s) {
  const auto rig = MakeStereoRig();
  const int n = o.keyframes_per_lap + o.extra_keyframes;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / o.keyframes_per_lap;
    Eigen::Matrix3d world_r_camera;
    world_r_camera.col(0) = Eigen::Vector3d(std::sin(a), 0, -std::cos(a));
    world_r_camera.col(1) = Eigen::Vector3d(0, 1, 0);
    world_r_camera.col(2) = Eigen::Vector3d(std::cos(a), 0, std::sin(a));
    const Eigen::Vector3d centre(2.0 * std::cos(a), 0.0, 2.0 * std::sin(a));
    s->true_camera_from_world.push_back(
        SE3d(world_r_camera, centre).Inverse() *
        SE3d(o.world_from_scenario.Inverse(), Eigen::Vector3d::Zero()));
  }
  s->map = s->atlas.current_map();
  s->synthetic = MakeMap(&s->atlas, scene, rig, s->true_camera_from_world, {});

  auto lock = MapEditor(&s->atlas).Write(MapEdit::kFixture);
  auto& kfs = s->synthetic.keyframes;
  // A chain spanning tree (the fixture picks parents by covisibility, which can form cycles).
  for (int k = 1; k < n; ++k) {
    if (KeyFrame* old = kfs[k]->parent()) old->EraseChild(lock, kfs[k].get());
    kfs[k]->ChangeParent(lock, kfs[k - 1].get());
  }
  // Cut the covisibility across the loop; remember what fusion will bring back.
  const int lap = o.keyframes_per_lap;
  std::vector<std::pair<int, int>> across;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      if (j - i <= lap / 2) continue;
      if (kfs[i]->Weight(kfs[j].get()) > 0) across.emplace_back(i, j);
      kfs[i]->EraseConnection(lock, kfs[j].get());
      kfs[j]->EraseConnection(lock, kfs[i].get());
    }
  }
  // Odometry-like drift: every step's relative motion is off by `delta` in the camera frame,
  // world_from_camera_drifted(k+1) = world_from_camera_drifted(k) * true_step(k) * delta.
  // D_k = world_drifted_from_world_true then grows by delta conjugated with the true pose.
  const Sim3d delta(o.drift_scale_per_keyframe,
                    SO3d::Exp(Eigen::Vector3d(0, o.drift_yaw_per_keyframe, 0)),
                    Eigen::Vector3d(o.drift_step_per_keyframe, 0, 0.5 * o.drift_step_per_keyframe));
  std::vector<Sim3d> drift(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const Sim3d world_from_camera(s->true_camera_from_world[k].Inverse());
    drift[k] =
        k == 0 ? Sim3d() : drift[k - 1] * world_from_camera * delta * world_from_camera.Inverse();
  }
  for (const auto& [id, mp] : s->map->map_points()) {
    const KeyFrameId ref = mp->reference_keyframe()->id() - kfs[0]->id();
    mp->SetPosition(lock, drift[static_cast<std::size_t>(ref)] * mp->position());
  }
  for (int k = 0; k < n; ++k) {
    const Sim3d camera_from_world = Sim3d(s->true_camera_from_world[k]) * drift[k].Inverse();
    kfs[k]->SetPose(lock, camera_from_world.ToSE3ScaledTranslation());
  }

  // The loop: last keyframe <-> the first-lap keyframe at the same angle. Neighbourhood: the
  // last keyframe and its covisibles (all on the late side after the cut).
  KeyFrame* current = kfs[n - 1].get();
  LoopCorrection& c = s->correction;
  c.current_keyframe = current->id();
  c.loop_keyframe = kfs[n - 1 - lap]->id();
  // The verified loop Sim3 ties the current keyframe to the loop keyframe as the map has it
  // (drifted by D_loop): S_cw corrected = S_cl * T_lw = T_cw * D_c * D_l^-1.
  const Sim3d current_corrected = Sim3d(current->camera_from_world()) * drift[n - 1] *
                                  drift[static_cast<std::size_t>(n - 1 - lap)].Inverse();
  std::vector<KeyFrame*> neighbourhood = current->ConnectedKeyFrames();
  neighbourhood.push_back(current);
  for (KeyFrame* kf : neighbourhood) {
    const Sim3d non_corrected(kf->camera_from_world());
    c.non_corrected_camera_from_world[kf->id()] = non_corrected;
    c.corrected_camera_from_world[kf->id()] =
        non_corrected * Sim3d(current->world_from_camera()) * current_corrected;
  }
  // CorrectLoop: move the neighbourhood's points and poses. Points created on the loop side
  // (the fixture shares points across the loop; in a real run these are the loop-side points
  // that fusion kept) stay where they are.
  const KeyFrameId late_side = kfs[static_cast<std::size_t>(n - 1 - lap / 2)]->id();
  for (KeyFrame* kf : neighbourhood) {
    const Sim3d& corrected = c.corrected_camera_from_world[kf->id()];
    const Sim3d& non_corrected = c.non_corrected_camera_from_world[kf->id()];
    for (const auto& mp : kf->map_points()) {
      if (!mp || c.corrected_points.count(mp->id()) > 0) continue;
      if (mp->reference_keyframe()->id() < late_side) continue;
      mp->SetPosition(lock, corrected.Inverse() * (non_corrected * mp->position()));
      c.corrected_points[mp->id()] = kf->id();
    }
    kf->SetPose(lock, corrected.ToSE3ScaledTranslation());
  }
  // Fusion restores the links across the loop with their true weights.
  std::set<KeyFrameId> in_neighbourhood;
  for (KeyFrame* kf : neighbourhood) in_neighbourhood.insert(kf->id());
  for (const auto& [i, j] : across) {
    if (in_neighbourhood.count(kfs[j]->id()) == 0) continue;  // not reached by fusion yet
    int weight = 0;
    for (const auto& mp : kfs[i]->map_points()) {
      if (mp && mp->IsInKeyFrame(kfs[j].get())) ++weight;
    }
    kfs[i]->AddConnection(lock, kfs[j].get(), weight);
    kfs[j]->AddConnection(lock, kfs[i].get(), weight);
    c.loop_connections[kfs[j]->id()].push_back(kfs[i]->id());
  }
}

}  // namespace pkslam::testing
