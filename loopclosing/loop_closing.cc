// LoopClosing: the thread, its queue and place detection (verification and confirmation).
#include "loopclosing/loop_closing.h"

#include <chrono>
#include <mutex>
#include <shared_mutex>

#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/wall_time.h"
#include "map_model/estimation/global_bundle_merge.h"
#include "map_model/estimation/inertial_bundle_collect.h"
#include "map_model/keyframe.h"
#include "map_model/keyframe_database.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"

namespace pkslam {

void LoopClosingOptions::Check() const {
  verifier.Check();
  PKSLAM_CHECK_OPTION(candidates > 0, "LoopClosing.candidates", "{}", candidates);
  PKSLAM_CHECK_OPTION(min_keyframes_mono > 0 && min_keyframes_stereo > 0,
                      "LoopClosing.min_keyframes", "{} / {}", min_keyframes_mono,
                      min_keyframes_stereo);
  PKSLAM_CHECK_OPTION(confirmations >= 1, "LoopClosing.confirmations", "{}", confirmations);
  PKSLAM_CHECK_OPTION(
      confirming_covisibles >= 0 && max_unconfirmed >= 0 && keyframes_after_loop >= 0,
      "LoopClosing.confirming_covisibles", "{} / {} / {}", confirming_covisibles, max_unconfirmed,
      keyframes_after_loop);
  PKSLAM_CHECK_OPTION(fuse_radius > 0, "LoopClosing.fuse_radius", "{}", fuse_radius);
  PKSLAM_CHECK_OPTION(inertial_max_tilt_rad > 0 && inertial_max_yaw_rad > 0,
                      "LoopClosing.inertial_max_tilt_rad / yaw", "{} / {}", inertial_max_tilt_rad,
                      inertial_max_yaw_rad);
  PKSLAM_CHECK_OPTION(max_loop_correction_m >= 0, "LoopClosing.max_loop_correction_m", "{}",
                      max_loop_correction_m);
  PKSLAM_CHECK_OPTION(num_threads > 0, "LoopClosing.num_threads", "{}", num_threads);
  global_ba_options.Check();
  PKSLAM_CHECK_OPTION(inertial_global_ba_max_keyframes >= 0 && inertial_global_ba_iterations >= 1,
                      "LoopClosing.inertial_global_ba", "{} / {}", inertial_global_ba_max_keyframes,
                      inertial_global_ba_iterations);
}

LoopClosing::LoopClosing(Atlas* atlas, Sensor sensor, MappingControl mapping,
                         LoopClosingOptions options)
    : atlas_(atlas), sensor_(sensor), mapping_(std::move(mapping)), options_(options) {
  PKSLAM_CHECK(atlas_ != nullptr, "loop closing needs an atlas");
  options_.verifier.fix_scale = !IsMonocular(sensor_);
  options_.Check();
  seed_ = options_.seed;
}

LoopClosing::~LoopClosing() { Finish(); }

void LoopClosing::Start() {
  if (options_.synchronous) return;
  PKSLAM_CHECK(!thread_.joinable(), "loop closing already started");
  thread_ = std::thread([this] { Run(); });
}

void LoopClosing::Finish() {
  {
    MutexLock lock(mutex_);
    finish_requested_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  // A global BA still running finishes and is merged back (the outputs should have it).
  if (gba_thread_.joinable()) gba_thread_.join();
}

void LoopClosing::InsertKeyFrame(const KeyFramePtr& kf) {
  if (options_.synchronous) {
    Process(kf);
    return;
  }
  {
    MutexLock lock(mutex_);
    queue_.push_back(kf);
  }
  wake_.notify_all();
}

void LoopClosing::WaitUntilIdle() {
  if (options_.synchronous) return;
  MutexLock lock(mutex_);
  while (!((queue_.empty() && !busy_) || !thread_.joinable())) idle_.wait(lock);
}

LoopClosingStats LoopClosing::stats() const {
  MutexLock lock(mutex_);
  return stats_;
}

void LoopClosing::Run() {
  MutexLock lock(mutex_);
  while (true) {
    while (!finish_requested_ && queue_.empty()) wake_.wait(lock);
    if (queue_.empty()) {
      if (finish_requested_) break;
      continue;
    }
    const KeyFramePtr kf = queue_.front();
    queue_.pop_front();
    busy_ = true;
    lock.unlock();
    Process(kf);
    lock.lock();
    busy_ = false;
    idle_.notify_all();
  }
  idle_.notify_all();
}

void LoopClosing::PauseMapping() {
  if (options_.synchronous || !mapping_.request_stop) return;
  mapping_.request_stop();
  while (!mapping_.is_stopped()) std::this_thread::sleep_for(std::chrono::microseconds(500));
}

void LoopClosing::ReleaseMapping() {
  if (options_.synchronous || !mapping_.release) return;
  mapping_.release();
}

void LoopClosing::Process(const KeyFramePtr& kf) {
  const auto start = std::chrono::steady_clock::now();
  double verification_ms = 0;
  std::optional<CommonRegion> region = Detect(kf, &verification_ms);
  {
    MutexLock lock(mutex_);
    stats_.detection_ms.push_back(WallMsSince(start));
    ++stats_.keyframes;
  }
  if (!region) return;
  pending_loop_.reset();
  pending_merge_.reset();
  LoopEvent event;
  event.t_ns = region->query->t_ns();
  event.query = region->query->id();
  event.matched = region->matched->id();
  event.matches = region->matches;
  event.detection_ms = verification_ms;
  bool merge = false;
  {
    auto lock = MapReader(*atlas_).Lock();
    if (region->query->map() == nullptr || region->matched->map() == nullptr) return;
    event.map = region->query->map()->id();
    event.matched_map = region->matched->map()->id();
    merge = region->query->map() != region->matched->map();
    if (!merge && !AcceptsInertialLoop(*region)) {
      MutexLock stats_lock(mutex_);
      ++stats_.rejected_inertial;
      return;
    }
    if (!merge && !AcceptsLoopCorrection(*region)) {
      MutexLock stats_lock(mutex_);
      ++stats_.rejected_implausible;
      return;
    }
  }
  const auto correct_start = std::chrono::steady_clock::now();
  Map* corrected = merge ? MergeMaps(*region, &event) : CorrectLoop(*region, &event);
  if (corrected == nullptr) return;
  last_loop_kf_id_ = event.query;
  event.correction_ms = WallMsSince(correct_start);
  PKSLAM_LOG_INFO(
      "{} at t = {:.3f} s: keyframe {} (map {}) <-> keyframe {} (map {}), {} matches, "
      "keyframe moved {:.3f} m, {:.1f} ms",
      merge ? "map merge" : "loop closed", static_cast<double>(event.t_ns) * 1e-9, event.query,
      event.map, event.matched, event.matched_map, event.matches, event.correction_m,
      event.correction_ms);
  std::size_t index = 0;
  {
    MutexLock lock(mutex_);
    auto& events = merge ? stats_.merges : stats_.loops;
    index = events.size();
    events.push_back(event);
  }
  StartGlobalBundle(corrected, merge, index);
}

std::optional<CommonRegion> LoopClosing::Detect(const KeyFramePtr& kf, double* verification_ms) {
  auto lock = MapReader(*atlas_).Lock();
  KeyFrameDatabase* database = atlas_->database();
  Map* map = kf->map();
  if (database == nullptr || map == nullptr || kf->IsBad()) return std::nullopt;
  // Inertial maps wait for their second inertial BA (ORB-SLAM3); small maps are not searched.
  if (IsInertial(sensor_) && !map->imu_status().inertial_ba2_done) return std::nullopt;
  const int min_keyframes =
      IsMonocular(sensor_) ? options_.min_keyframes_mono : options_.min_keyframes_stereo;
  if (map->NumKeyFrames() < min_keyframes) return std::nullopt;

  // Pending regions: does this keyframe see them too?
  for (const bool merge : {true, false}) {
    std::optional<CommonRegion>& pending = merge ? pending_merge_ : pending_loop_;
    int& failures = merge ? pending_merge_failures_ : pending_loop_failures_;
    if (!pending) continue;
    const Map* matched_map = pending->matched->map();
    const bool still_valid = pending->query->map() == map && matched_map != nullptr &&
                             !pending->matched->IsBad() && (matched_map != map) == merge;
    if (!still_valid) {
      pending.reset();
      continue;
    }
    const auto t = std::chrono::steady_clock::now();
    std::vector<MapPointPtr> matched;
    const Sim3d carried = CarryOver(*pending, *kf);
    const int n = CountRegionMatches(*pending, *kf, carried, options_.verifier, &matched);
    *verification_ms += WallMsSince(t);
    if (n >= options_.verifier.min_confirmation_matches) {
      pending->query = kf;
      pending->query_camera_from_world = carried;
      pending->matched_points = std::move(matched);
      pending->matches = n;
      ++pending->confirmations;
      failures = 0;
      if (pending->confirmations >= options_.confirmations) {
        std::optional<CommonRegion> accepted = std::move(pending);
        pending.reset();
        return accepted;
      }
    } else if (++failures > options_.max_unconfirmed) {
      PKSLAM_LOG_DEBUG("dropped an unconfirmed {} candidate (keyframe {})",
                       merge ? "merge" : "loop", pending->matched->id());
      pending.reset();
      failures = 0;
      MutexLock stats_lock(mutex_);
      ++stats_.rejected_regions;
    }
  }

  const bool search_loops =
      !pending_loop_ && (last_loop_kf_id_ == kInvalidId ||
                         kf->id() >= last_loop_kf_id_ + options_.keyframes_after_loop);
  const bool search_merges = !pending_merge_ && options_.merge_maps && map == atlas_->current_map();
  if (!search_loops && !search_merges) return std::nullopt;
  const LoopAndMergeCandidates candidates =
      database->DetectLoopAndMergeCandidates(kf.get(), options_.candidates);
  for (const bool merge : {true, false}) {
    if (merge ? !search_merges : !search_loops) continue;
    for (const PlaceCandidate& c : merge ? candidates.merge : candidates.loop) {
      const auto t = std::chrono::steady_clock::now();
      std::optional<CommonRegion> region =
          VerifyCandidate(kf, c.keyframe, options_.verifier, seed_++);
      if (region) {
        region->confirmations +=
            ConfirmByCovisibles(*region, options_.confirming_covisibles, options_.verifier);
      }
      *verification_ms += WallMsSince(t);
      {
        MutexLock stats_lock(mutex_);
        ++stats_.tested_candidates;
        if (region) ++stats_.verified_regions;
      }
      if (!region) continue;
      PKSLAM_LOG_DEBUG("{} candidate: keyframe {} <-> {}, {} matches, {} confirmations",
                       merge ? "merge" : "loop", kf->id(), region->matched->id(), region->matches,
                       region->confirmations);
      if (region->confirmations >= options_.confirmations) return region;
      (merge ? pending_merge_ : pending_loop_) = std::move(region);
      (merge ? pending_merge_failures_ : pending_loop_failures_) = 0;
      break;
    }
  }
  return std::nullopt;
}

void LoopClosing::StartGlobalBundle(Map* map, bool merge, std::size_t index) {
  if (!options_.global_ba) return;
  StopGlobalBundle();
  {
    MutexLock lock(mutex_);
    ++stats_.global_ba_started;
  }
  if (options_.synchronous) {
    RunGlobalBundle(map, merge, index);
    return;
  }
  gba_running_.store(true);
  gba_thread_ = std::thread([this, map, merge, index] { RunGlobalBundle(map, merge, index); });
}

void LoopClosing::StopGlobalBundle() {
  if (!gba_thread_.joinable()) return;
  gba_abort_.store(true);
  gba_thread_.join();
  gba_abort_.store(false);
}

void LoopClosing::RunGlobalBundle(Map* map, bool merge, std::size_t index) {
  const auto start = std::chrono::steady_clock::now();
  const std::atomic<bool>* abort = options_.synchronous ? nullptr : &gba_abort_;
  // Inertial maps: the full visual-inertial BA over the temporal chain (ORB-SLAM3).
  InertialBundleOptions inertial_options;
  inertial_options.iterations_first = options_.inertial_global_ba_iterations;
  inertial_options.iterations_second = 0;
  inertial_options.num_threads = options_.global_ba_options.num_threads;
  InertialBundleProblem inertial;
  BundleProblem problem;
  {
    auto lock = MapReader(*atlas_).Lock();
    if (IsInertial(sensor_) && map->imu_status().imu_initialized &&
        map->NumKeyFrames() <= options_.inertial_global_ba_max_keyframes) {
      KeyFrame* newest = nullptr;
      for (auto it = map->keyframes().rbegin(); it != map->keyframes().rend() && !newest; ++it) {
        if (!it->second->IsBad()) newest = it->second.get();
      }
      if (newest != nullptr) inertial = CollectFullInertialBundle(newest, inertial_options);
      if (inertial.edges.empty()) inertial = InertialBundleProblem{};
    }
    if (inertial.empty()) problem = CollectGlobalBundle(lock, *map);
  }
  const bool use_inertial = !inertial.empty();
  const BundleProblem& visual = use_inertial ? inertial.visual : problem;
  PKSLAM_LOG_INFO("{}global BA of map {} started: {} keyframes, {} points",
                  use_inertial ? "inertial " : "", map->id(), visual.keyframes.size(),
                  visual.points.size());
  InertialBundleResult inertial_result;
  BundleResult result;
  if (use_inertial) {
    inertial_result = SolveInertialBundle(inertial, inertial_options, abort);
  } else {
    result = SolveBundle(problem, options_.global_ba_options, abort);
  }
  const bool aborted = use_inertial ? inertial_result.visual.aborted : result.aborted;
  bool applied = false;
  if (!aborted && !gba_abort_.load()) {
    PauseMapping();
    {
      auto lock = MapEditor(atlas_).Write(MapEdit::kGlobalBundle);
      // A newer loop or merge may have aborted us in the meantime (then it owns the map).
      if (!gba_abort_.load()) {
        const auto gravity_before = GravityInCameras(*map);
        if (use_inertial) {
          MergeGlobalBundle(
              lock, map, inertial.visual,
              [&] { ApplyInertialBundle(lock, map, inertial, inertial_result); }, true);
        } else {
          MergeGlobalBundle(lock, map, problem, result);
        }
        applied = true;
        if (IsInertial(sensor_) && map->imu_status().imu_initialized) {
          map->RecordWorldChange(lock, {});
          PKSLAM_LOG_INFO("global BA of map {}: largest keyframe tilt change {:.2e} rad", map->id(),
                          MaxTiltChange(*map, gravity_before));
        }
      }
    }
    ReleaseMapping();
  }
  const double ms = WallMsSince(start);
  {
    MutexLock lock(mutex_);
    if (applied) {
      ++stats_.global_ba_finished;
      auto& events = merge ? stats_.merges : stats_.loops;
      if (index < events.size()) events[index].global_ba_ms = ms;
    } else {
      ++stats_.global_ba_aborted;
    }
  }
  PKSLAM_LOG_INFO("global BA {} after {:.0f} ms", applied ? "merged back" : "aborted", ms);
  gba_running_.store(false);
}

}  // namespace pkslam
