// ORB-SLAM's OptimizeEssentialGraph: after a loop is detected and the current keyframe's
// neighbourhood has been corrected, a pose graph over all live keyframes of the map spreads
// the correction: Sim3 (7-DoF, monocular), SE3 (6-DoF, stereo/RGB-D) or yaw + translation
// (4-DoF, inertial maps with the IMU initialised: ORB-SLAM3's OptimizeEssentialGraph4DoF)
// vertices; edges of the spanning tree, the existing loop edges, strong covisibility
// (weight >= 100), the new loop connections and, for inertial maps, each keyframe's link to
// the previous keyframe of the temporal chain (KeyFrame::imu.previous()), each holding the
// relative pose before the correction (for the corrected neighbourhood: its non-corrected
// pose). The map's first keyframe is fixed. Map points follow the correction of their
// reference keyframe; keyframe velocities (inertial state) turn with their keyframe.
//
// Three phases, as estimators/optim/bundle_adjustment.h, so the solver runs without the Atlas
// lock: Collect (shared lock) -> Solve (no lock) -> Apply (exclusive lock). The solver here
// takes and returns values; Collect and Apply are map_model/estimation/essential_graph_collect.h.
//
// Parameterisation: per keyframe a rotation block (quaternion), a translation block and a
// log-scale block of its camera_from_world Sim3; the Dof switch decides which blocks move
// (SE3 keeps every log-scale at 0). kYawTranslation keeps the scale at 1 and puts the
// rotation block on estimators/optim/yaw_manifold.h's manifold, which only turns the world about
// its gravity axis z: roll and pitch of every keyframe stay exactly as they were. Its Collect also
// reduces each given correction (corrected vs non-corrected pose) to yaw + translation about
// the keyframe's centre, so a loop measurement with a roll/pitch error cannot tilt the map.
//
// Cost (loop_closing_benchmark, Release, 1 thread): 40 keyframes / 188 edges ~10 ms; 184
// keyframes / 4465 edges ~0.3 s CPU, about 2/3 autodiff Jacobians and 1/3 sparse Cholesky.
// kYawTranslation (BM_EssentialGraphYawTranslation, loaded machine): ~7 ms / ~0.21 s CPU.
#pragma once

#include <Eigen/Core>
#include <map>
#include <vector>

#include "core/geometry/sim3.h"
#include "core/util/ids.h"

namespace pkslam {

enum class PoseGraphDof {
  kSim3,  // 7 DoF: rotation, translation, scale (monocular)
  kSE3,   // 6 DoF: scale fixed (stereo, RGB-D)
  // 4 DoF: yaw about the world z (gravity) axis and translation; scale fixed (inertial maps
  // with the IMU initialised; their world has gravity along -z).
  kYawTranslation,
};

struct EssentialGraphOptions {
  PoseGraphDof dof = PoseGraphDof::kSim3;
  // Covisibility edges (and new loop connections other than current<->loop) need at least
  // this many shared points (ORB-SLAM: 100).
  int min_covisibility_weight = 100;
  // Levenberg-Marquardt iterations (ORB-SLAM: 20).
  int iterations = 20;
  // Ceres threads (1 in deterministic mode).
  int num_threads = 1;
  // Edge error: the Sim3 logarithm of S_ji * S_iw * S_jw^-1 (ORB-SLAM's EdgeSim3), or, when
  // false, its translation, rotation log and log-scale (equal to first order, cheaper).
  bool exact_log = true;

  void Check() const;
};

// What loop closing hands over (ORB-SLAM's CorrectedSim3, NonCorrectedSim3, LoopConnections).
struct LoopCorrection {
  KeyFrameId current_keyframe = kInvalidId;  // the keyframe that detected the loop
  KeyFrameId loop_keyframe = kInvalidId;     // its match on the other side of the loop
  // The current keyframe's neighbourhood: Sim3 camera_from_world after the correction (from
  // the verified loop Sim3) and before it (the SE3 pose it had, scale 1).
  std::map<KeyFrameId, Sim3d> corrected_camera_from_world;
  std::map<KeyFrameId, Sim3d> non_corrected_camera_from_world;
  // Links created by loop fusion: keyframe -> keyframes it is newly connected to.
  std::map<KeyFrameId, std::vector<KeyFrameId>> loop_connections;
  // Points the caller already moved with the neighbourhood's correction -> the keyframe whose
  // correction moved them (ORB-SLAM's mnCorrectedReference); other points follow their
  // reference keyframe.
  std::map<MapPointId, KeyFrameId> corrected_points;
};

struct EssentialGraphProblem {
  // kInertial: keyframe -> previous keyframe of the temporal chain (kYawTranslation only;
  // pairs already joined by a spanning-tree edge are not repeated).
  enum class EdgeKind { kSpanningTree, kLoop, kNewLoop, kCovisibility, kInertial };
  struct Vertex {
    KeyFrameId keyframe_id = kInvalidId;
    Sim3d camera_from_world;  // initial estimate (corrected where known)
    // The pose before the loop correction (non-corrected where given, else the initial one):
    // the world its keyframe's velocity is expressed in.
    Sim3d camera_from_world_before;
    bool fixed = false;
  };
  struct Edge {
    int i = 0;  // vertex indices
    int j = 0;
    Sim3d j_from_i;  // measurement S_ji = S_jw * S_iw^-1 before the correction
    EdgeKind kind = EdgeKind::kSpanningTree;
  };
  struct Point {
    MapPointId point_id = kInvalidId;
    int vertex = 0;  // the keyframe whose correction it follows
  };

  MapId map_id = kInvalidId;  // the map it was collected from
  PoseGraphDof dof = PoseGraphDof::kSim3;
  std::vector<Vertex> vertices;  // keyframe id order
  std::vector<Edge> edges;
  std::vector<Point> points;  // map point id order
  std::map<KeyFrameId, int> vertex_of;

  int CountEdges(EdgeKind kind) const;
};

struct EssentialGraphResult {
  std::vector<Sim3d> camera_from_world;  // optimised, per vertex
  int iterations = 0;
  double initial_cost = 0;
  double final_cost = 0;
};

// Pure computation.
EssentialGraphResult SolveEssentialGraph(const EssentialGraphProblem& problem,
                                         const EssentialGraphOptions& options);
}  // namespace pkslam
