#include "mapping/keyframe_steps.h"

#include <chrono>
#include <mutex>
#include <shared_mutex>
#include <utility>
#include <vector>

#include "core/util/cpu_time.h"
#include "core/util/log.h"
#include "core/util/wall_time.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "mapping/inertial_culling.h"
#include "mapping/keyframe_admission.h"
#include "mapping/keyframe_culling.h"
#include "mapping/neighbour_fusion.h"
#include "mapping/neighbour_triangulation.h"

namespace pkslam {

KeyFrameSteps::KeyFrameSteps(Atlas* atlas, std::shared_ptr<const CameraRig> rig,
                             const LocalMappingOptions& options, KeyFrameStepHooks hooks)
    : atlas_(atlas), rig_(std::move(rig)), options_(options), hooks_(std::move(hooks)) {}

KeyFrameStepReport KeyFrameSteps::Run(const KeyFramePtr& kf) {
  KeyFrameStepReport report;
  // The step boundary comes before every step that changes the map or asks whether tracking
  // queued a keyframe: both then happen at a data time tracking has reached, as in a live run.
  hooks_.step_boundary();
  Admit(kf);
  report.points_culled = CullRecentPoints(kf);
  report.points_created = CreateNewPoints(kf);
  hooks_.step_boundary();
  if (!hooks_.keyframe_waiting()) Fuse(kf);
  hooks_.step_boundary();
  if (hooks_.keyframe_waiting() || hooks_.stopping()) return report;
  AdjustLocalMap(kf, &report);
  hooks_.step_boundary();
  if (options_.cull_keyframes) report.keyframes_culled = CullKeyFrames(kf);
  return report;
}

void KeyFrameSteps::Admit(const KeyFramePtr& kf) {
  auto lock = MapEditor(atlas_).Write(MapEdit::kProcessKeyFrame);
  // Created by tracking for this keyframe (stereo/RGB-D): watched for a while.
  for (const MapPointPtr& mp : AdmitKeyFrame(lock, atlas_, kf.get())) recent_points_.Watch(mp);
}

int KeyFrameSteps::CullRecentPoints(const KeyFramePtr& kf) {
  auto lock = MapEditor(atlas_).Write(MapEdit::kCullPoints);
  RecentPointRule rule;
  rule.min_found_ratio = options_.min_found_ratio;
  rule.min_observations = IsMonocular(rig_->sensor) ? 2 : 3;
  return recent_points_.Cull(lock, kf->id(), rule);
}

int KeyFrameSteps::CreateNewPoints(const KeyFramePtr& kf) {
  const bool mono = IsMonocular(rig_->sensor);
  NeighbourTriangulationOptions search;
  search.neighbours =
      mono ? options_.triangulation_neighbours_mono : options_.triangulation_neighbours_stereo;
  search.monocular = mono;
  search.stop = hooks_.keyframe_waiting;
  search.work = hooks_.work;
  std::vector<TriangulatedPoint> found;
  {
    auto lock = MapReader(*atlas_).Lock();
    if (kf->IsBad() || kf->map() == nullptr) return 0;
    found = TriangulateWithNeighbours(*kf, search);
  }
  if (found.empty()) return 0;
  hooks_.pace();
  auto lock = MapEditor(atlas_).Write(MapEdit::kCreatePoints);
  const std::vector<MapPointPtr> added = AddTriangulatedPoints(lock, atlas_, kf.get(), found);
  for (const MapPointPtr& mp : added) recent_points_.Watch(mp);
  return static_cast<int>(added.size());
}

void KeyFrameSteps::Fuse(const KeyFramePtr& kf) {
  auto lock = MapEditor(atlas_).Write(MapEdit::kFuse);
  NeighbourFusionOptions fusion;
  fusion.first_ring = IsMonocular(rig_->sensor) ? 30 : 10;
  fusion.work = hooks_.work;
  FuseWithNeighbours(lock, kf.get(), fusion);
}

void KeyFrameSteps::AdjustLocalMap(const KeyFramePtr& kf, KeyFrameStepReport* report) {
  int keyframes = 0;
  {
    auto lock = MapReader(*atlas_).Lock();
    keyframes = kf->map() != nullptr ? kf->map()->NumKeyFrames() : 0;
  }
  if (keyframes <= 2) return;
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = ThreadCpuSeconds();
  if (!IsInertial(rig_->sensor) || !LocalInertialBundleAdjustment(kf, report)) {
    report->ba_aborted = LocalBundleAdjustment(kf);
  }
  report->ba_ms = WallMsSince(start);
  report->ba_cpu_ms = 1e3 * (ThreadCpuSeconds() - cpu_start);
}

bool KeyFrameSteps::LocalBundleAdjustment(const KeyFramePtr& kf) {
  BundleProblem problem;
  {
    auto lock = MapReader(*atlas_).Lock();
    if (kf->IsBad() || kf->map() == nullptr) return false;
    problem = CollectLocalBundle(lock, kf.get(), options_.ba);
  }
  if (problem.empty()) return false;
  const BundleResult result = SolveBundle(problem, options_.ba, hooks_.abort, hooks_.work);
  hooks_.pace();
  auto lock = MapEditor(atlas_).Write(MapEdit::kApplyBundle);
  // A map merged away while the solver ran takes its keyframes with it: nothing to write.
  if (Map* map = atlas_->FindMap(problem.map_id)) ApplyBundle(lock, map, problem, result);
  return result.aborted;
}

bool KeyFrameSteps::LocalInertialBundleAdjustment(const KeyFramePtr& kf,
                                                  KeyFrameStepReport* report) {
  InertialBundleProblem problem;
  InertialBundleOptions ba = options_.inertial.local_ba;
  ba.num_threads = options_.ba.num_threads;
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kApplyInertialBundle);
    if (kf->IsBad() || kf->map() == nullptr || !kf->map()->imu_status().imu_initialized)
      return false;
    StartMissingInertialStates(lock, kf.get());
  }
  {
    auto lock = MapReader(*atlas_).Lock();
    if (kf->IsBad() || kf->map() == nullptr) return false;
    problem = CollectLocalInertialBundle(kf.get(), ba);
  }
  if (problem.empty() || problem.edges.empty()) return false;
  const InertialBundleResult result = SolveInertialBundle(problem, ba, hooks_.abort, hooks_.work);
  auto lock = MapEditor(atlas_).Write(MapEdit::kApplyInertialBundle);
  Map* map = atlas_->FindMap(problem.visual.map_id);
  if (kf->map() == nullptr || map == nullptr) return true;
  ApplyInertialBundle(lock, map, problem, result);
  kf->map()->RecordWorldChange(lock, {});
  lock.unlock();
  PKSLAM_LOG_DEBUG(
      "local inertial BA at kf {}: {} iterations, cost {:.1f} -> {:.1f}, anchor {}, next prior "
      "information trace pose {:.3g} velocity {:.3g} gyro {:.3g} accel {:.3g}",
      kf->id(), result.visual.iterations, result.visual.initial_cost, result.visual.final_cost,
      problem.anchor_prior ? "with prior" : "fixed",
      result.next_prior ? result.next_prior->information.topLeftCorner<6, 6>().trace() : 0.0,
      result.next_prior ? result.next_prior->information.block<3, 3>(6, 6).trace() : 0.0,
      result.next_prior ? result.next_prior->information.block<3, 3>(9, 9).trace() : 0.0,
      result.next_prior ? result.next_prior->information.block<3, 3>(12, 12).trace() : 0.0);
  report->ba_aborted = result.visual.aborted;
  report->inertial_ba = true;
  report->inertial_ba_with_prior = problem.anchor_prior.has_value();
  return true;
}

int KeyFrameSteps::CullKeyFrames(const KeyFramePtr& kf) {
  auto lock = MapEditor(atlas_).Write(MapEdit::kCullKeyFrames);
  if (kf->IsBad() || kf->map() == nullptr) return 0;
  // Inertial maps: the temporal chain's spacing rules (mapping/inertial_culling.h).
  const bool inertial = IsInertial(rig_->sensor);
  const InertialCullingOptions& inertial_culling = options_.inertial.culling;
  if (inertial && !inertial_culling.enabled) return 0;
  const bool mono = IsMonocular(rig_->sensor);
  KeyFrameCullingInput input;
  input.redundancy.share = !inertial ? options_.culling_redundancy
                           : mono    ? inertial_culling.redundancy_mono
                                     : inertial_culling.redundancy_stereo;
  input.redundancy.observers = options_.culling_observers;
  input.redundancy.max_depth = mono ? -1.0 : rig_->th_depth;
  input.inertial = inertial ? &inertial_culling : nullptr;
  input.abort = hooks_.abort;
  return CullRedundantKeyFrames(lock, kf.get(), input);
}

}  // namespace pkslam
