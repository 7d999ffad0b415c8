// LocalMapper: IMU initialisation stages and local inertial BA (see mapping/inertial_mapping.h).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <shared_mutex>

#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/wall_time.h"
#include "estimators/inertial/inertial_initializer.h"
#include "imu/preintegration.h"
#include "map_model/estimation/global_bundle_merge.h"
#include "map_model/estimation/gravity_refinement_collect.h"
#include "map_model/estimation/inertial_init_collect.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "mapping/local_mapper.h"

namespace pkslam {
void InertialMappingOptions::Check() const {
  PKSLAM_CHECK_OPTION(min_keyframes >= 3, "inertial.min_keyframes", "{}", min_keyframes);
  PKSLAM_CHECK_OPTION(min_time_stereo_s >= 0 && min_time_mono_s >= 0, "inertial.min_time",
                      "{} / {}", min_time_stereo_s, min_time_mono_s);
  PKSLAM_CHECK_OPTION(mono_min_travel >= 0, "inertial.mono_min_travel", "{}", mono_min_travel);
  PKSLAM_CHECK_OPTION(init_gyro_prior >= 0 && init_accel_prior_mono >= 0 &&
                          init_accel_prior_stereo >= 0 && viba1_gyro_prior >= 0 &&
                          viba1_accel_prior >= 0 && viba2_gyro_prior >= 0 && viba2_accel_prior >= 0,
                      "inertial.priors", "{}", "negative");
  PKSLAM_CHECK_OPTION(viba1_s > 0 && viba2_s > viba1_s, "inertial.viba", "{} / {}", viba1_s,
                      viba2_s);
  PKSLAM_CHECK_OPTION(moving_distance >= 0 && moving_angle_rad >= 0 && moving_max_interval_s > 0,
                      "inertial.moving", "{} / {} / {}", moving_distance, moving_angle_rad,
                      moving_max_interval_s);
  PKSLAM_CHECK_OPTION(full_ba_iterations >= 1, "inertial.full_ba_iterations", "{}",
                      full_ba_iterations);
  local_ba.Check();
  culling.Check();
}

void LocalMapper::InertialStep(const KeyFramePtr& kf) {
  bool initialized = false;
  bool ba1 = false;
  bool ba2 = false;
  double step_s = 0;  // the interval from the previous keyframe, if the body moved over it
  std::int64_t init_t_ns = 0;
  const InertialMappingOptions& o = options_.inertial;
  {
    auto lock = MapReader(*atlas_).Lock();
    if (kf->IsBad() || kf->map() == nullptr) return;
    const Map* map = kf->map();
    initialized = map->imu_status().imu_initialized;
    ba1 = map->imu_status().inertial_ba1_done;
    ba2 = map->imu_status().inertial_ba2_done;
    init_t_ns = map->imu_status().imu_init_t_ns;
    const KeyFrameMotion motion = motion_clock_.Observe(*kf, initialized && !ba2, o);
    step_s = motion.step_s;
    if (motion.slow_motion) slow_motion_.store(true);
  }
  const bool mono = IsMonocular(rig_->sensor);
  if (!initialized) {
    initializing_imu_.store(true);
    if (InitializeImu(kf, o.init_gyro_prior,
                      mono ? o.init_accel_prior_mono : o.init_accel_prior_stereo, 0)) {
      motion_clock_.Restart();
    }
    initializing_imu_.store(false);
    return;
  }
  // The refinements wait for motion time since the initialisation, not clock time: a platform
  // standing still adds nothing that separates the accelerometer bias from gravity.
  const double moving_s = motion_clock_.Advance(step_s);
  const double since =
      o.viba_motion_time ? moving_s : static_cast<double>(kf->t_ns() - init_t_ns) * 1e-9;
  // The steps below move every state of the map (MergeGlobalBundle), which would make a
  // calibration adjustment solving in its own thread find its map moved and be discarded; they
  // wait for it to end (a later keyframe runs them).
  if (calibration_running_.load()) return;
  auto mark = [&](bool second) {
    auto lock = MapEditor(atlas_).Write(MapEdit::kInertialInitialisation);
    if (kf->map() == nullptr) return;
    MapImuStatus& status = kf->map()->mutable_imu_status();
    (second ? status.inertial_ba2_done : status.inertial_ba1_done) = true;
  };
  if (!ba1 && since > o.viba1_s) {
    initializing_imu_.store(true);
    if (InitializeImu(kf, o.viba1_gyro_prior, o.viba1_accel_prior, 1)) mark(false);
    initializing_imu_.store(false);
  } else if (ba1 && !ba2 && since > o.viba2_s) {
    initializing_imu_.store(true);
    if (InitializeImu(kf, o.viba2_gyro_prior, o.viba2_accel_prior, 2)) mark(true);
    initializing_imu_.store(false);
  } else if (ba2 && o.gravity_refinement) {
    RefineGravity(kf);
  }
}

void LocalMapper::RefineGravity(const KeyFramePtr& kf) {
  const InertialMappingOptions& o = options_.inertial;
  InertialBundleOptions ba = o.local_ba;
  ba.iterations_first = o.gravity_refinement_iterations;
  ba.iterations_second = 0;
  ba.num_threads = options_.ba.num_threads;
  // A queued keyframe comes first (a monocular map gets its points only here); the next
  // keyframe tries again.
  if (HasQueued()) return;
  std::optional<GravityRefinementProblem> problem;
  {
    auto lock = MapReader(*atlas_).Lock();
    GravityRefinementRule rule;
    rule.min_observability = o.gravity_refinement_min;
    rule.step = o.gravity_refinement_step;
    rule.max_keyframes = o.gravity_refinement_max_keyframes;
    problem = CollectGravityRefinement(kf.get(), rule, ba);
  }
  if (!problem || problem->bundle.edges.empty()) return;
  GravityRefinementStat stat;
  stat.observability = problem->observability;
  stat.t_ns = kf->t_ns();
  stat.keyframes = static_cast<int>(problem->bundle.edges.size()) + 1;
  const auto start = std::chrono::steady_clock::now();
  // A full inertial BA takes hundreds of ms, during which a monocular map gets no new points
  // (mono-inertial V1_02 replay with live timing: mapping busy 350 ms in a fast turn, inliers
  // 215 -> 31, tracking lost). Tracking may interrupt it like a local BA; the best iterate so
  // far is applied (each accepted iteration lowers the cost), or nothing if none was made.
  const InertialBundleResult result = SolveInertialBundle(problem->bundle, ba, &abort_ba_, &work_);
  if (result.visual.aborted && result.visual.iterations == 0) {
    PKSLAM_LOG_DEBUG("gravity refinement at t = {:.2f} s interrupted before its first step",
                     kf->t_s());
    return;
  }
  Eigen::Vector3d accel_bias;
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kInertialInitialisation);
    Map* map = kf->map();
    if (map == nullptr || kf->IsBad() || map->change_index() != problem->change_index) {
      // A loop correction or merge moved the map meanwhile: the result is stale; the next
      // keyframe tries again.
      PKSLAM_LOG_INFO("gravity refinement at t = {:.2f} s dropped: the map moved meanwhile",
                      kf->t_s());
      MutexLock stats_lock(mutex_);
      ++stats_.gravity_refinements_dropped;
      return;
    }
    stat.tilt_change_rad = ApplyGravityRefinement(lock, map, *kf, *problem, result);
    accel_bias = kf->imu().state.bias.accel;
  }
  stat.ms = WallMsSince(start);
  PKSLAM_LOG_INFO(
      "gravity refinement at t = {:.2f} s over {} keyframes (tilt observability {:.2f}): gravity "
      "moved {:.2f} mrad, cost {:.1f} -> {:.1f}, accel bias ({:.4f} {:.4f} {:.4f}), {:.0f} ms{}",
      kf->t_s(), stat.keyframes, stat.observability, 1e3 * stat.tilt_change_rad,
      result.visual.initial_cost, result.visual.final_cost, accel_bias.x(), accel_bias.y(),
      accel_bias.z(), stat.ms,
      result.visual.aborted
          ? fmt::format(" (interrupted after {} iterations)", result.visual.iterations)
          : std::string());
  MutexLock stats_lock(mutex_);
  stats_.gravity_refinements.push_back(stat);
}

bool LocalMapper::InitializeImu(const KeyFramePtr& kf, double gyro_prior, double accel_prior,
                                int stage) {
  const bool refinement = stage > 0;
  const InertialMappingOptions& o = options_.inertial;
  const bool mono = IsMonocular(rig_->sensor);
  std::optional<InertialInitProblem> problem;
  {
    auto lock = MapReader(*atlas_).Lock();
    InertialInitRule rule;
    rule.min_keyframes = o.min_keyframes;
    rule.min_time_s = mono ? o.min_time_mono_s : o.min_time_stereo_s;
    if (mono && !refinement) rule.min_travel = o.mono_min_travel;
    problem = CollectInertialInit(kf.get(), rule);
  }
  if (!problem) return false;
  // The chain's newest keyframe: kf, or one tracking created after it.
  const KeyFramePtr newest = problem->newest != nullptr ? problem->newest : kf;
  InertialInitializerOptions init_options;
  init_options.estimate_scale = mono;
  init_options.gyro_bias_prior_information = gyro_prior;
  init_options.accel_bias_prior_information = accel_prior;
  init_options.gravity_magnitude = o.local_ba.gravity_magnitude;
  const auto start = std::chrono::steady_clock::now();
  const InertialInitResult r = InitializeInertial(problem->keyframes, problem->preintegrations,
                                                  problem->initial_bias, init_options);
  if (!r.success) {
    PKSLAM_LOG_WARN("IMU initialisation at t = {:.2f} s failed: {}", kf->t_s(), r.message);
    return false;
  }
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kInertialInitialisation);
    Map* map = kf->map();
    if (map == nullptr || kf->IsBad()) return false;
    ApplyInertialInit(lock, map, *problem, r, refinement, kf->t_ns());
  }
  const double ms = WallMsSince(start);
  PKSLAM_LOG_INFO(
      "IMU {} at t = {:.2f} s over {} keyframes: scale {:.4f}, gyro bias ({:.5f} "
      "{:.5f} {:.5f}), accel bias ({:.4f} {:.4f} {:.4f}), {:.0f} ms",
      refinement ? "refinement" : "initialisation", kf->t_s(), problem->chain.size(), r.scale,
      r.bias.gyro.x(), r.bias.gyro.y(), r.bias.gyro.z(), r.bias.accel.x(), r.bias.accel.y(),
      r.bias.accel.z(), ms);
  FullInertialBundleAdjustment(newest, gyro_prior, accel_prior);
  ImuStageSnapshot snapshot;
  snapshot.t_ns = kf->t_ns();
  snapshot.stage = stage;
  snapshot.scale = r.scale;
  {
    auto lock = MapReader(*atlas_).Lock();
    snapshot.bias = kf->imu().state.bias;
    for (KeyFrame* k : InertialChain::EndingAt(newest.get(), 0)) {
      snapshot.world_from_body.emplace_back(k->t_ns(), k->world_from_body());
    }
  }
  MutexLock stats_lock(mutex_);
  stats_.imu_stages.push_back(std::move(snapshot));
  return true;
}

void LocalMapper::FullInertialBundleAdjustment(const KeyFramePtr& kf, double gyro_prior,
                                               double accel_prior) {
  InertialBundleProblem problem;
  InertialBundleOptions ba = options_.inertial.local_ba;
  ba.iterations_first = options_.inertial.full_ba_iterations;
  ba.iterations_second = options_.inertial.full_ba_iterations;
  ba.num_threads = options_.ba.num_threads;
  {
    auto lock = MapReader(*atlas_).Lock();
    if (kf->IsBad() || kf->map() == nullptr) return;
    problem = CollectFullInertialBundle(kf.get(), ba);
  }
  if (problem.empty()) return;
  problem.shared_bias = true;
  problem.gyro_prior_information = gyro_prior;
  problem.accel_prior_information = accel_prior;
  const InertialBundleResult result = SolveInertialBundle(problem, ba, nullptr, &work_);
  auto lock = MapEditor(atlas_).Write(MapEdit::kInertialInitialisation);
  Map* map = atlas_->FindMap(problem.visual.map_id);
  if (kf->map() == nullptr || map == nullptr) return;
  ApplyFullInertialBundle(lock, map, *kf, problem, result);
}

bool LocalMapper::LocalInertialBundleAdjustment(const KeyFramePtr& kf) {
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
  const InertialBundleResult result = SolveInertialBundle(problem, ba, &abort_ba_, &work_);
  auto lock = MapEditor(atlas_).Write(MapEdit::kApplyInertialBundle);
  Map* map = atlas_->FindMap(problem.visual.map_id);
  if (kf->map() == nullptr || map == nullptr) return true;
  ApplyInertialBundle(lock, map, problem, result);
  kf->map()->RecordWorldChange({});
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
  MutexLock stats_lock(mutex_);
  if (result.visual.aborted) ++stats_.ba_aborted;
  ++(problem.anchor_prior ? stats_.inertial_ba_with_prior : stats_.inertial_ba_fixed_anchor);
  return true;
}

}  // namespace pkslam
