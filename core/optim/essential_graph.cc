#include "core/optim/essential_graph.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <set>
#include <utility>

#include "core/map/keyframe.h"
#include "core/map/map.h"
#include "core/map/map_point.h"
#include "core/optim/ceres_setup.h"
#include "core/optim/yaw_manifold.h"
#include "core/util/error.h"

namespace pkslam {
namespace {

// Parameter layout of one vertex: quaternion (Eigen order x y z w), translation, log-scale of
// its camera_from_world Sim3.
constexpr int kQ = 0;
constexpr int kT = 4;
constexpr int kS = 7;
constexpr int kVertexSize = 8;

template <typename T>
Sim3<T> VertexSim3(const T* q, const T* t, const T* log_s) {
  using std::exp;
  const Eigen::Quaternion<T> quat(q[3], q[0], q[1], q[2]);
  return Sim3<T>(exp(log_s[0]), SO3<T>(quat), Eigen::Matrix<T, 3, 1>(t[0], t[1], t[2]));
}

// ORB-SLAM's EdgeSim3 error: log(S_ji * S_iw * S_jw^-1), zero when the two vertices keep the
// relative pose they had before the correction. Identity information, as ORB-SLAM.
// With exact_log = false the error is [t; Log(R); log s] of the same transform, which agrees
// with the logarithm to first order and skips the series of Sim3's V-matrix.
struct RelativeSim3Cost {
  RelativeSim3Cost(const Sim3d& j_from_i, bool exact_log)
      : j_from_i(j_from_i), exact_log(exact_log) {}

  template <typename T>
  bool operator()(const T* qi, const T* ti, const T* si, const T* qj, const T* tj, const T* sj,
                  T* residual) const {
    using std::log;
    const Sim3<T> i_from_world = VertexSim3(qi, ti, si);
    const Sim3<T> j_from_world = VertexSim3(qj, tj, sj);
    const Sim3<T> error = j_from_i.cast<T>() * i_from_world * j_from_world.Inverse();
    if (exact_log) {
      const typename Sim3<T>::Tangent xi = error.Log();
      for (int k = 0; k < 7; ++k) residual[k] = xi(k);
    } else {
      const Eigen::Matrix<T, 3, 1> phi = error.so3().Log();
      for (int k = 0; k < 3; ++k) {
        residual[k] = error.translation()(k);
        residual[3 + k] = phi(k);
      }
      residual[6] = log(error.scale());
    }
    return true;
  }

  Sim3d j_from_i;
  bool exact_log;
};

// Ceres takes ownership of cost functions and their functors through raw pointers.
template <typename Functor, int... kDims>
ceres::CostFunction* MakeAutoDiff(Functor functor) {
  auto owned = std::make_unique<Functor>(std::move(functor));
  return std::make_unique<ceres::AutoDiffCostFunction<Functor, kDims...>>(owned.release())
      .release();
}

std::pair<KeyFrameId, KeyFrameId> Ordered(KeyFrameId a, KeyFrameId b) {
  return {std::min(a, b), std::max(a, b)};
}

}  // namespace

void EssentialGraphOptions::Check() const {
  PKSLAM_CHECK_OPTION(min_covisibility_weight >= 1, "min_covisibility_weight", "{}",
                      min_covisibility_weight);
  PKSLAM_CHECK_OPTION(iterations >= 1, "iterations", "{}", iterations);
  PKSLAM_CHECK_OPTION(num_threads >= 1, "num_threads", "{}", num_threads);
}

int EssentialGraphProblem::CountEdges(EdgeKind kind) const {
  return static_cast<int>(
      std::count_if(edges.begin(), edges.end(), [kind](const Edge& e) { return e.kind == kind; }));
}

EssentialGraphProblem CollectEssentialGraph(Map* map, const LoopCorrection& correction,
                                            const EssentialGraphOptions& options) {
  options.Check();
  PKSLAM_CHECK(map != nullptr, "null map");
  EssentialGraphProblem problem;
  problem.map = map;
  problem.dof = options.dof;

  for (const auto& [id, kf] : map->keyframes()) {
    if (kf->IsBad()) continue;
    EssentialGraphProblem::Vertex v;
    v.keyframe = kf;
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
    const KeyFrameId id = problem.vertices[v].keyframe->id();
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
    const KeyFrame* kf_i = problem.vertices[i].keyframe.get();
    for (const KeyFrameId id_j : sorted) {
      const int j = vertex(id_j);
      if (j < 0 || j == i) continue;
      const bool is_loop_pair =
          id_i == correction.current_keyframe && id_j == correction.loop_keyframe;
      if (!is_loop_pair &&
          kf_i->Weight(problem.vertices[j].keyframe.get()) < options.min_covisibility_weight) {
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
    const KeyFrame* kf = problem.vertices[i].keyframe.get();
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
    const KeyFrame* previous = kf->imu.previous;
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
    if (v >= 0) problem.points.push_back({mp, v});
  }
  return problem;
}

EssentialGraphResult SolveEssentialGraph(const EssentialGraphProblem& problem,
                                         const EssentialGraphOptions& options) {
  options.Check();
  EssentialGraphResult result;
  const std::size_t n = problem.vertices.size();
  std::vector<double> params(n * kVertexSize);
  for (std::size_t v = 0; v < n; ++v) {
    const Sim3d& s = problem.vertices[v].camera_from_world;
    double* p = &params[v * kVertexSize];
    const Eigen::Quaterniond& q = s.so3().quaternion();
    p[kQ + 0] = q.x();
    p[kQ + 1] = q.y();
    p[kQ + 2] = q.z();
    p[kQ + 3] = q.w();
    for (int k = 0; k < 3; ++k) p[kT + k] = s.translation()(k);
    p[kS] = std::log(s.scale());
  }
  auto read = [&params](std::size_t v) {
    const double* p = &params[v * kVertexSize];
    return Sim3d(std::exp(p[kS]), SO3d(Eigen::Quaterniond(p[kQ + 3], p[kQ], p[kQ + 1], p[kQ + 2])),
                 Eigen::Vector3d(p[kT], p[kT + 1], p[kT + 2]));
  };
  if (problem.edges.empty()) {
    for (std::size_t v = 0; v < n; ++v) result.camera_from_world.push_back(read(v));
    return result;
  }

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  // Shared by all rotation blocks.
  ceres::EigenQuaternionManifold quaternion_manifold;
  YawQuaternionManifold yaw_manifold;
  const bool yaw_only = problem.dof == PoseGraphDof::kYawTranslation;
  ceres::Problem ceres_problem(problem_options);
  for (std::size_t v = 0; v < n; ++v) {
    double* p = &params[v * kVertexSize];
    ceres_problem.AddParameterBlock(
        p + kQ, 4, yaw_only ? static_cast<ceres::Manifold*>(&yaw_manifold) : &quaternion_manifold);
    ceres_problem.AddParameterBlock(p + kT, 3);
    ceres_problem.AddParameterBlock(p + kS, 1);
    const bool fixed = problem.vertices[v].fixed;
    if (fixed) {
      ceres_problem.SetParameterBlockConstant(p + kQ);
      ceres_problem.SetParameterBlockConstant(p + kT);
    }
    if (fixed || problem.dof != PoseGraphDof::kSim3)
      ceres_problem.SetParameterBlockConstant(p + kS);
  }
  for (const auto& e : problem.edges) {
    double* pi = &params[static_cast<std::size_t>(e.i) * kVertexSize];
    double* pj = &params[static_cast<std::size_t>(e.j) * kVertexSize];
    ceres::CostFunction* cost = MakeAutoDiff<RelativeSim3Cost, 7, 4, 3, 1, 4, 3, 1>(
        RelativeSim3Cost(e.j_from_i, options.exact_log));
    ceres_problem.AddResidualBlock(cost, nullptr, pi + kQ, pi + kT, pi + kS, pj + kQ, pj + kT,
                                   pj + kS);
  }

  const ceres::Solver::Options solver_options =
      SolverOptions(ceres::SPARSE_NORMAL_CHOLESKY, options.iterations, options.num_threads);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &ceres_problem, &summary);
  result.iterations = static_cast<int>(summary.iterations.size());
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  for (std::size_t v = 0; v < n; ++v) result.camera_from_world.push_back(read(v));
  return result;
}

void ApplyEssentialGraph(const EssentialGraphProblem& problem, const EssentialGraphResult& result) {
  PKSLAM_CHECK(result.camera_from_world.size() == problem.vertices.size(),
               "{} results for {} vertices", result.camera_from_world.size(),
               problem.vertices.size());
  Map* map = problem.map;
  // world_new_from_world_old of each vertex's neighbourhood.
  std::vector<Sim3d> correction(problem.vertices.size());
  for (std::size_t v = 0; v < problem.vertices.size(); ++v) {
    correction[v] = result.camera_from_world[v].Inverse() * problem.vertices[v].camera_from_world;
  }
  auto vertex_of = [&problem](const KeyFrame* kf) {
    auto it = problem.vertex_of.find(kf->id());
    return it != problem.vertex_of.end() && problem.vertices[it->second].keyframe.get() == kf
               ? it->second
               : -1;
  };
  // Keyframes created after Collect move with their nearest ancestor in the graph.
  const int max_steps = map->NumKeyFrames() + static_cast<int>(map->retired_keyframes().size());
  // Velocities live in the world frame: they turn (and scale) with the keyframe's world.
  auto move_velocity = [](KeyFrame* kf, const Sim3d& world_new_from_world_old) {
    if (!kf->imu.state.valid) return;
    kf->imu.state.velocity_world = world_new_from_world_old.scale() *
                                   (world_new_from_world_old.so3() * kf->imu.state.velocity_world);
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
      kf->SetPose(result.camera_from_world[v].ToSE3ScaledTranslation());
      move_velocity(kf.get(), result.camera_from_world[v].Inverse() *
                                  problem.vertices[v].camera_from_world_before);
      continue;
    }
    const int a = ancestor_vertex(kf->parent());
    if (a < 0) continue;
    const Sim3d moved = Sim3d(kf->camera_from_world()) * correction[a].Inverse();
    kf->SetPose(moved.ToSE3ScaledTranslation());
    move_velocity(kf.get(), correction[a]);
  }

  std::map<MapPointId, int> point_vertex;
  for (const auto& p : problem.points) point_vertex[p.point->id()] = p.vertex;
  for (const auto& [id, mp] : map->map_points()) {
    if (mp->IsBad()) continue;
    int v = -1;
    if (auto it = point_vertex.find(id); it != point_vertex.end()) {
      v = it->second;
    } else if (mp->reference_keyframe() != nullptr) {
      v = ancestor_vertex(mp->reference_keyframe());
    }
    if (v < 0) continue;
    mp->SetPosition(correction[static_cast<std::size_t>(v)] * mp->position());
    mp->UpdateNormalAndDepth();
  }
  map->IncreaseChangeIndex();
}

}  // namespace pkslam
