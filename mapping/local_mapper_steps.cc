// LocalMapper: the per-keyframe steps (ORB-SLAM3's LocalMapping::Run body).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <shared_mutex>
#include <unordered_set>

#include "core/util/cpu_time.h"
#include "core/util/log.h"
#include "core/util/wall_time.h"
#include "map_model/keyframe.h"
#include "map_model/keyframe_database.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"
#include "mapping/inertial_culling.h"
#include "mapping/keyframe_culling.h"
#include "mapping/local_mapper.h"
#include "mapping/triangulation.h"

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
  if (IsInertial(rig_->sensor) && !IsStoppedOrStopRequested()) InertialStep(kf);
  StepBoundary();
  if (options_.calibration.enabled && !IsStoppedOrStopRequested()) RefineCalibration(kf);
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
  if (kf->IsBad() || kf->map() == nullptr) return;
  const auto& points = kf->map_points();
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const MapPointPtr mp = points[i];
    if (!mp || mp->IsBad()) continue;
    if (!mp->IsInKeyFrame(kf.get())) {
      // A point tracked by the frame: the keyframe becomes one of its observers.
      mp->AddObservation(kf.get(), i);
      mp->UpdateNormalAndDepth();
      mp->ComputeDistinctiveDescriptor();
    } else {
      // Created by tracking for this keyframe (stereo/RGB-D): watch it for a while.
      recent_points_.push_back(mp);
    }
  }
  kf->UpdateConnections();
  // Findable by relocalisation and place recognition from now on.
  if (KeyFrameDatabase* database = atlas_->database()) database->Add(kf.get());
}

void LocalMapper::CullRecentPoints(const KeyFramePtr& kf) {
  auto lock = MapEditor(atlas_).Write(MapEdit::kCullPoints);
  const int min_observations = IsMonocular(rig_->sensor) ? 2 : 3;
  int culled = 0;
  std::erase_if(recent_points_, [&](const MapPointPtr& mp) {
    if (mp->IsBad()) return true;
    const KeyFrameId age = kf->id() - mp->first_keyframe_id();
    if (mp->FoundRatio() < options_.min_found_ratio) {
      mp->SetBad();
      ++culled;
      return true;
    }
    if (age >= 2 && mp->NumObservations() <= min_observations) {
      mp->SetBad();
      ++culled;
      return true;
    }
    return age >= 3;  // survived its probation
  });
  lock.unlock();
  MutexLock stats_lock(mutex_);
  stats_.points_culled += culled;
}

void LocalMapper::CreateNewMapPoints(const KeyFramePtr& kf) {
  const bool mono = IsMonocular(rig_->sensor);
  const int n_neighbours =
      mono ? options_.triangulation_neighbours_mono : options_.triangulation_neighbours_stereo;
  std::vector<TriangulatedPoint> created;
  std::vector<KeyFrame*> neighbours;
  {
    auto lock = MapReader(*atlas_).Lock();
    if (kf->IsBad() || kf->map() == nullptr) return;
    neighbours = kf->BestCovisibles(n_neighbours);
    const OrbMatcher matcher(0.6, false);
    std::unordered_set<int> claimed;  // keypoints of kf already given a point this round
    for (std::size_t n = 0; n < neighbours.size(); ++n) {
      if (n > 0 && HasQueued()) break;
      KeyFrame* other = neighbours[n];
      if (!HasTriangulationBaseline(*kf, *other, mono)) continue;
      work_.Add(WorkKind::kTriangulationPair,
                static_cast<std::int64_t>(kf->keypoints_undistorted().size() +
                                          other->keypoints_undistorted().size()));
      const auto pairs = matcher.SearchForTriangulation(*kf, *other);
      for (const auto& [i1, i2] : pairs) {
        if (claimed.count(i1) > 0) continue;
        if (auto p = TriangulatePair(*kf, i1, *other, i2, mono)) {
          claimed.insert(i1);
          created.push_back({*p, other, i1, i2});
        }
      }
    }
  }
  if (created.empty()) return;
  PaceToTracker();  // not StepBoundary: the points were triangulated with the present rig
  auto lock = MapEditor(atlas_).Write(MapEdit::kCreatePoints);
  Map* map = kf->map();
  if (kf->IsBad() || map == nullptr) return;
  int added = 0;
  for (const auto& c : created) {
    // Tracking never fills existing keyframes' slots and we are the only other writer, but a
    // neighbour may have been retired by loop closing's fusion meanwhile.
    if (c.other->IsBad() || kf->map_point(c.index1) || c.other->map_point(c.index2)) continue;
    auto mp = std::make_shared<MapPoint>(atlas_->NextMapPointId(), c.position, kf.get(), map);
    mp->AddObservation(kf.get(), c.index1);
    mp->AddObservation(c.other, c.index2);
    kf->AddMapPoint(mp, c.index1);
    c.other->AddMapPoint(mp, c.index2);
    mp->ComputeDistinctiveDescriptor();
    mp->UpdateNormalAndDepth();
    map->AddMapPoint(mp);
    recent_points_.push_back(mp);
    ++added;
  }
  lock.unlock();
  MutexLock stats_lock(mutex_);
  stats_.points_created += added;
}

void LocalMapper::SearchInNeighbours(const KeyFramePtr& kf) {
  auto lock = MapEditor(atlas_).Write(MapEdit::kFuse);
  if (kf->IsBad() || kf->map() == nullptr) return;
  const int n = IsMonocular(rig_->sensor) ? 30 : 10;
  std::vector<KeyFrame*> targets;
  std::unordered_set<KeyFrameId> in_targets{kf->id()};
  for (KeyFrame* neighbour : kf->BestCovisibles(n)) {
    if (neighbour->IsBad() || !in_targets.insert(neighbour->id()).second) continue;
    targets.push_back(neighbour);
  }
  const std::size_t first_ring = targets.size();
  for (std::size_t i = 0; i < first_ring; ++i) {
    for (KeyFrame* second : targets[i]->BestCovisibles(20)) {
      if (second->IsBad() || !in_targets.insert(second->id()).second) continue;
      targets.push_back(second);
    }
  }
  const OrbMatcher matcher;
  // Our points into the neighbours...
  const std::vector<MapPointPtr> ours = kf->GoodMapPoints();
  for (KeyFrame* target : targets) matcher.Fuse(target, ours);
  // ...and the neighbours' points into us.
  std::vector<MapPointPtr> candidates;
  std::unordered_set<MapPointId> seen;
  for (const auto& mp : kf->GoodMapPoints()) seen.insert(mp->id());
  for (KeyFrame* target : targets) {
    for (const auto& mp : target->map_points()) {
      if (!mp || mp->IsBad() || !seen.insert(mp->id()).second) continue;
      candidates.push_back(mp);
    }
  }
  matcher.Fuse(kf.get(), candidates);
  work_.Add(WorkKind::kFuseProjection,
            static_cast<std::int64_t>(ours.size() * targets.size() + candidates.size()));
  for (const auto& mp : kf->GoodMapPoints()) {
    mp->ComputeDistinctiveDescriptor();
    mp->UpdateNormalAndDepth();
  }
  kf->UpdateConnections();
}

void LocalMapper::LocalBundleAdjustment(const KeyFramePtr& kf) {
  BundleProblem problem;
  {
    auto lock = MapReader(*atlas_).Lock();
    if (kf->IsBad() || kf->map() == nullptr) return;
    problem = CollectLocalBundle(kf.get(), options_.ba);
  }
  if (problem.empty()) return;
  const BundleResult result = SolveBundle(problem, options_.ba, &abort_ba_, &work_);
  PaceToTracker();  // not StepBoundary: the result is written back over the states it read
  auto lock = MapEditor(atlas_).Write(MapEdit::kApplyBundle);
  // A map merged away while the solver ran takes its keyframes with it: nothing to write.
  if (Map* map = atlas_->FindMap(problem.map_id)) ApplyBundle(map, problem, result);
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
