// Collect and Apply phases of the essential graph (the map-facing parts); the solver is
// estimators/optim/essential_graph.cc.
#include "map_model/estimation/essential_graph_collect.h"

#include <algorithm>
#include <map>
#include <set>
#include <utility>

#include "core/util/error.h"
#include "estimators/optim/yaw_manifold.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"

namespace pkslam {
namespace {

std::pair<KeyFrameId, KeyFrameId> Ordered(KeyFrameId a, KeyFrameId b) {
  return {std::min(a, b), std::max(a, b)};
}

}  // namespace

EssentialGraphProblem CollectEssentialGraph(Map* map, const LoopCorrection& correction,
                                            const EssentialGraphOptions& options) {
  options.Check();
  PKSLAM_CHECK(map != nullptr, "null map");
  EssentialGraphProblem problem;
  problem.map_id = map->id();
  problem.dof = options.dof;

  // The vertices' keyframes, by vertex index (the problem itself names them by id).
  std::vector<const KeyFrame*> vertex_keyframes;
  auto keyframe_of = [&vertex_keyframes](int v) {
    return vertex_keyframes[static_cast<std::size_t>(v)];
  };
  for (const auto& [id, kf] : map->keyframes()) {
    if (kf->IsBad()) continue;
    vertex_keyframes.push_back(kf.get());
    EssentialGraphProblem::Vertex v;
    v.keyframe_id = id;
    auto it = correction.corrected_camera_from_world.find(id);
    v.camera_from_world = it != correction.corrected_camera_from_world.end()
                              ? it->second
                              : Sim3d(kf->camera_from_world());
    if (options.dof != PoseGraphDof::kSim3) v.camera_from_world.set_scale(1.0);
    auto non = correction.non_corrected_camera_from_world.find(id);
    v.camera_from_world_before =
        non != correction.non_corrected_camera_from_world.end() ? non->second : v.camera_from_world;
    if (options.dof == PoseGraphDof::kYawTranslation &&
        it != correction.corrected_camera_from_world.end() &&
        non != correction.non_corrected_camera_from_world.end()) {
      // Only yaw and translation of the given correction: the keyframe keeps its roll/pitch.
      const Sim3d world_new_from_world_old = it->second.Inverse() * non->second;
      const Eigen::Vector3d centre_old = non->second.Inverse().translation();
      v.camera_from_world =
          non->second * ProjectToYawTranslation(world_new_from_world_old, centre_old).Inverse();
    }
    v.fixed = kf.get() == map->origin();
    problem.vertex_of[id] = static_cast<int>(problem.vertices.size());
    problem.vertices.push_back(std::move(v));
  }
  auto vertex = [&problem](KeyFrameId id) {
    auto it = problem.vertex_of.find(id);
    return it == problem.vertex_of.end() ? -1 : it->second;
  };
  // The pose a keyframe had before the correction: relative poses are measured from these.
  auto before = [&](int v) -> Sim3d {
    const KeyFrameId id = problem.vertices[v].keyframe_id;
    auto it = correction.non_corrected_camera_from_world.find(id);
    return it != correction.non_corrected_camera_from_world.end()
               ? it->second
               : problem.vertices[v].camera_from_world;
  };
  auto add_edge = [&problem](int i, int j, const Sim3d& j_from_i,
                             EssentialGraphProblem::EdgeKind kind) {
    problem.edges.push_back({i, j, j_from_i, kind});
  };

  // New loop connections: measured between the corrected estimates (both sides are already
  // consistent across the loop). Weak links are skipped except current <-> loop keyframe.
  std::set<std::pair<KeyFrameId, KeyFrameId>> inserted;
  for (const auto& [id_i, linked] : correction.loop_connections) {
    const int i = vertex(id_i);
    if (i < 0) continue;
    std::vector<KeyFrameId> sorted = linked;
    std::sort(sorted.begin(), sorted.end());
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    const KeyFrame* kf_i = keyframe_of(i);
    for (const KeyFrameId id_j : sorted) {
      const int j = vertex(id_j);
      if (j < 0 || j == i) continue;
      const bool is_loop_pair =
          id_i == correction.current_keyframe && id_j == correction.loop_keyframe;
      if (!is_loop_pair && kf_i->Weight(keyframe_of(j)) < options.min_covisibility_weight) {
        continue;
      }
      add_edge(
          i, j,
          problem.vertices[j].camera_from_world * problem.vertices[i].camera_from_world.Inverse(),
          EssentialGraphProblem::EdgeKind::kNewLoop);
      inserted.insert(Ordered(id_i, id_j));
    }
  }

  for (int i = 0; i < static_cast<int>(problem.vertices.size()); ++i) {
    const KeyFrame* kf = keyframe_of(i);
    const KeyFrameId id = kf->id();
    const Sim3d world_from_i = before(i).Inverse();
    // Spanning tree.
    const KeyFrame* parent = kf->parent();
    if (parent != nullptr) {
      const int p = vertex(parent->id());
      if (p >= 0) {
        add_edge(i, p, before(p) * world_from_i, EssentialGraphProblem::EdgeKind::kSpanningTree);
      }
    }
    // Loop edges of earlier loops (each pair once, from its younger keyframe).
    for (const auto& [loop_id, loop_kf] : kf->loop_edges()) {
      if (loop_id >= id) continue;
      const int l = vertex(loop_id);
      if (l >= 0) add_edge(i, l, before(l) * world_from_i, EssentialGraphProblem::EdgeKind::kLoop);
    }
    // Inertial maps: the previous keyframe of the temporal chain (ORB-SLAM3's 4-DoF graph).
    const KeyFrame* previous = kf->imu().previous();
    if (options.dof == PoseGraphDof::kYawTranslation && previous != nullptr && !previous->IsBad() &&
        previous != parent && previous->parent() != kf &&
        inserted.count(Ordered(id, previous->id())) == 0) {
      const int p = vertex(previous->id());
      if (p >= 0) {
        add_edge(i, p, before(p) * world_from_i, EssentialGraphProblem::EdgeKind::kInertial);
        inserted.insert(Ordered(id, previous->id()));
      }
    }
    // Strong covisibility, once per pair, not duplicating the edges above.
    for (const KeyFrame* n : kf->CovisiblesWithWeightAtLeast(options.min_covisibility_weight)) {
      if (n == parent || n->IsBad() || n->id() >= id) continue;
      if (kf->children().count(n->id()) > 0 || kf->loop_edges().count(n->id()) > 0) continue;
      if (inserted.count(Ordered(id, n->id())) > 0) continue;
      const int c = vertex(n->id());
      if (c >= 0) {
        add_edge(i, c, before(c) * world_from_i, EssentialGraphProblem::EdgeKind::kCovisibility);
      }
    }
  }

  // Points follow the keyframe that corrected them, else their reference keyframe, else the
  // first observing keyframe in the graph.
  for (const auto& [id, mp] : map->map_points()) {
    if (mp->IsBad()) continue;
    int v = -1;
    if (auto it = correction.corrected_points.find(id); it != correction.corrected_points.end()) {
      v = vertex(it->second);
    }
    if (v < 0 && mp->reference_keyframe() != nullptr) v = vertex(mp->reference_keyframe()->id());
    for (auto it = mp->observations().begin(); v < 0 && it != mp->observations().end(); ++it) {
      v = vertex(it->first);
    }
    if (v >= 0) problem.points.push_back({id, v});
  }
  return problem;
}

void ApplyEssentialGraph(const MapWriteLock& lock, Map* map, const EssentialGraphProblem& problem,
                         const EssentialGraphResult& result) {
  RequireWriteLock(lock, "ApplyEssentialGraph");
  PKSLAM_CHECK(map != nullptr, "ApplyEssentialGraph without a map");
  PKSLAM_CHECK(problem.map_id == kInvalidId || problem.map_id == map->id(),
               "essential graph of map {} applied to map {}", problem.map_id, map->id());
  PKSLAM_CHECK(result.camera_from_world.size() == problem.vertices.size(),
               "{} results for {} vertices", result.camera_from_world.size(),
               problem.vertices.size());
  // world_new_from_world_old of each vertex's neighbourhood.
  std::vector<Sim3d> correction(problem.vertices.size());
  for (std::size_t v = 0; v < problem.vertices.size(); ++v) {
    correction[v] = result.camera_from_world[v].Inverse() * problem.vertices[v].camera_from_world;
  }
  auto vertex_of = [&problem](const KeyFrame* kf) {
    auto it = problem.vertex_of.find(kf->id());
    return it != problem.vertex_of.end() ? it->second : -1;
  };
  // Keyframes created after Collect move with their nearest ancestor in the graph.
  const int max_steps = map->NumKeyFrames() + static_cast<int>(map->retired_keyframes().size());
  // Velocities live in the world frame: they turn (and scale) with the keyframe's world.
  auto move_velocity = [&lock](KeyFrame* kf, const Sim3d& world_new_from_world_old) {
    if (!kf->imu().state.valid) return;
    kf->mutable_imu(lock).state.velocity_world =
        world_new_from_world_old.scale() *
        (world_new_from_world_old.so3() * kf->imu().state.velocity_world);
  };
  auto ancestor_vertex = [&](const KeyFrame* kf) {
    for (int step = 0; kf != nullptr && step <= max_steps; ++step, kf = kf->parent()) {
      const int v = vertex_of(kf);
      if (v >= 0) return v;
    }
    return -1;
  };

  for (const auto& [id, kf] : map->keyframes()) {
    if (kf->IsBad()) continue;
    const int v = vertex_of(kf.get());
    if (v >= 0) {
      kf->SetPose(lock, result.camera_from_world[v].ToSE3ScaledTranslation());
      move_velocity(kf.get(), result.camera_from_world[v].Inverse() *
                                  problem.vertices[v].camera_from_world_before);
      continue;
    }
    const int a = ancestor_vertex(kf->parent());
    if (a < 0) continue;
    const Sim3d moved = Sim3d(kf->camera_from_world()) * correction[a].Inverse();
    kf->SetPose(lock, moved.ToSE3ScaledTranslation());
    move_velocity(kf.get(), correction[a]);
  }

  std::map<MapPointId, int> point_vertex;
  for (const auto& p : problem.points) point_vertex[p.point_id] = p.vertex;
  for (const auto& [id, mp] : map->map_points()) {
    if (mp->IsBad()) continue;
    int v = -1;
    if (auto it = point_vertex.find(id); it != point_vertex.end()) {
      v = it->second;
    } else if (mp->reference_keyframe() != nullptr) {
      v = ancestor_vertex(mp->reference_keyframe());
    }
    if (v < 0) continue;
    mp->SetPosition(lock, correction[static_cast<std::size_t>(v)] * mp->position());
    mp->UpdateNormalAndDepth(lock);
  }
  map->IncreaseChangeIndex(lock);
}

}  // namespace pkslam
