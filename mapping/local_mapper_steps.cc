// LocalMapper: the per-keyframe steps (ORB-SLAM3's LocalMapping::Run body).
#include <chrono>
#include <mutex>
#include <shared_mutex>

#include "core/util/cpu_time.h"
#include "core/util/log.h"
#include "core/util/wall_time.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "mapping/inertial_culling.h"
#include "mapping/keyframe_admission.h"
#include "mapping/keyframe_culling.h"
#include "mapping/local_mapper.h"
#include "mapping/neighbour_fusion.h"
#include "mapping/neighbour_triangulation.h"

namespace pkslam {

void LocalMapper::ProcessNext() {
  KeyFramePtr kf;
  {
    MutexLock lock(mutex_);
    if (queue_.empty()) return;
    kf = queue_.front();
    queue_.pop_front();
  }
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = ThreadCpuSeconds();
  const WorkCounts work_start = work_.Snapshot();
  work_.Add(WorkKind::kKeyFrame, 1);
  abort_ba_.store(false);
  // StepBoundary (live emulation on the work clock) before every step that changes the map or
  // asks whether tracking queued a keyframe: both then happen at a data time tracking has
  // reached, as in a live run; so does applying an adjustment solved in the calibration thread.
  StepBoundary();
  ProcessNewKeyFrame(kf);
  CullRecentPoints(kf);
  CreateNewMapPoints(kf);
  double ba_ms = 0;
  double ba_cpu_ms = 0;
  StepBoundary();
  if (!HasQueued()) {
    SearchInNeighbours(kf);
  }
  StepBoundary();
  if (!HasQueued() && !IsStoppedOrStopRequested()) {
    int keyframes = 0;
    {
      auto lock = MapReader(*atlas_).Lock();
      keyframes = kf->map() != nullptr ? kf->map()->NumKeyFrames() : 0;
    }
    if (keyframes > 2) {
      const auto ba_start = std::chrono::steady_clock::now();
      const double ba_cpu_start = ThreadCpuSeconds();
      if (!IsInertial(rig_->sensor) || !LocalInertialBundleAdjustment(kf)) {
        LocalBundleAdjustment(kf);
      }
      ba_ms = WallMsSince(ba_start);
      ba_cpu_ms = 1e3 * (ThreadCpuSeconds() - ba_cpu_start);
    }
    StepBoundary();
    if (options_.cull_keyframes) CullKeyFrames(kf);
  }
  StepBoundary();
  if (IsInertial(rig_->sensor) && !IsStoppedOrStopRequested()) inertial_stages_.Step(kf);
  StepBoundary();
  if (options_.calibration.enabled && !IsStoppedOrStopRequested()) {
    calibrator_.Step(kf, HasQueued(), !options_.calibration.own_thread || !thread_.joinable(),
                     &abort_ba_, &work_);
  }
  StepBoundary();
  {
    MutexLock lock(mutex_);
    stats_.keyframe_ms.push_back(WallMsSince(start));
    stats_.ba_ms.push_back(ba_ms);
    stats_.keyframe_cpu_ms.push_back(1e3 * (ThreadCpuSeconds() - cpu_start));
    stats_.ba_cpu_ms.push_back(ba_cpu_ms);
    stats_.keyframe_work.push_back(work_.Snapshot() - work_start);
  }
  if (consumer_) consumer_(kf);
}

void LocalMapper::ProcessNewKeyFrame(const KeyFramePtr& kf) {
  auto lock = MapEditor(atlas_).Write(MapEdit::kProcessKeyFrame);
  // Created by tracking for this keyframe (stereo/RGB-D): watched for a while.
  for (const MapPointPtr& mp : AdmitKeyFrame(lock, atlas_, kf.get())) recent_points_.Watch(mp);
}

void LocalMapper::CullRecentPoints(const KeyFramePtr& kf) {
  auto lock = MapEditor(atlas_).Write(MapEdit::kCullPoints);
  RecentPointRule rule;
  rule.min_found_ratio = options_.min_found_ratio;
  rule.min_observations = IsMonocular(rig_->sensor) ? 2 : 3;
  const int culled = recent_points_.Cull(lock, kf->id(), rule);
  lock.unlock();
  MutexLock stats_lock(mutex_);
  stats_.points_culled += culled;
}

void LocalMapper::CreateNewMapPoints(const KeyFramePtr& kf) {
  const bool mono = IsMonocular(rig_->sensor);
  NeighbourTriangulationOptions search;
  search.neighbours =
      mono ? options_.triangulation_neighbours_mono : options_.triangulation_neighbours_stereo;
  search.monocular = mono;
  search.stop = [this] { return HasQueued(); };
  search.work = &work_;
  std::vector<TriangulatedPoint> found;
  {
    auto lock = MapReader(*atlas_).Lock();
    if (kf->IsBad() || kf->map() == nullptr) return;
    found = TriangulateWithNeighbours(*kf, search);
  }
  if (found.empty()) return;
  PaceToTracker();  // not StepBoundary: the points were triangulated with the present rig
  auto lock = MapEditor(atlas_).Write(MapEdit::kCreatePoints);
  const std::vector<MapPointPtr> added = AddTriangulatedPoints(lock, atlas_, kf.get(), found);
  for (const MapPointPtr& mp : added) recent_points_.Watch(mp);
  lock.unlock();
  MutexLock stats_lock(mutex_);
  stats_.points_created += static_cast<int>(added.size());
}

void LocalMapper::SearchInNeighbours(const KeyFramePtr& kf) {
  auto lock = MapEditor(atlas_).Write(MapEdit::kFuse);
  NeighbourFusionOptions fusion;
  fusion.first_ring = IsMonocular(rig_->sensor) ? 30 : 10;
  fusion.work = &work_;
  FuseWithNeighbours(lock, kf.get(), fusion);
}

void LocalMapper::LocalBundleAdjustment(const KeyFramePtr& kf) {
  BundleProblem problem;
  {
    auto lock = MapReader(*atlas_).Lock();
    if (kf->IsBad() || kf->map() == nullptr) return;
    problem = CollectLocalBundle(lock, kf.get(), options_.ba);
  }
  if (problem.empty()) return;
  const BundleResult result = SolveBundle(problem, options_.ba, &abort_ba_, &work_);
  PaceToTracker();  // not StepBoundary: the result is written back over the states it read
  auto lock = MapEditor(atlas_).Write(MapEdit::kApplyBundle);
  // A map merged away while the solver ran takes its keyframes with it: nothing to write.
  if (Map* map = atlas_->FindMap(problem.map_id)) ApplyBundle(lock, map, problem, result);
  if (result.aborted) {
    lock.unlock();
    MutexLock stats_lock(mutex_);
    ++stats_.ba_aborted;
  }
}

void LocalMapper::CullKeyFrames(const KeyFramePtr& kf) {
  auto lock = MapEditor(atlas_).Write(MapEdit::kCullKeyFrames);
  if (kf->IsBad() || kf->map() == nullptr) return;
  // Inertial maps: the temporal chain's spacing rules (mapping/inertial_culling.h).
  const bool inertial = IsInertial(rig_->sensor);
  const InertialCullingOptions& inertial_culling = options_.inertial.culling;
  if (inertial && !inertial_culling.enabled) return;
  const bool mono = IsMonocular(rig_->sensor);
  KeyFrameCullingInput input;
  input.redundancy.share = !inertial ? options_.culling_redundancy
                           : mono    ? inertial_culling.redundancy_mono
                                     : inertial_culling.redundancy_stereo;
  input.redundancy.observers = options_.culling_observers;
  input.redundancy.max_depth = mono ? -1.0 : rig_->th_depth;
  input.inertial = inertial ? &inertial_culling : nullptr;
  input.abort = &abort_ba_;
  const int culled = CullRedundantKeyFrames(lock, kf.get(), input);
  lock.unlock();
  MutexLock stats_lock(mutex_);
  stats_.keyframes_culled += culled;
}

}  // namespace pkslam
