// Local mapping's whole-map inertial stages (mapping/inertial_stages.h).
#include "mapping/inertial_stages.h"

#include <fmt/format.h>

#include <chrono>
#include <optional>
#include <string>

#include "core/util/log.h"
#include "core/util/wall_time.h"
#include "estimators/inertial/inertial_initializer.h"
#include "imu/preintegration.h"
#include "map_model/estimation/global_bundle_merge.h"
#include "map_model/estimation/gravity_refinement_collect.h"
#include "map_model/estimation/inertial_bundle_collect.h"
#include "map_model/estimation/inertial_init_collect.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"

namespace pkslam {

InertialStages::InertialStages(Atlas* atlas, Sensor sensor, InertialMappingOptions options,
                               int solver_threads, InertialStageHooks hooks)
    : atlas_(atlas),
      sensor_(sensor),
      options_(std::move(options)),
      solver_threads_(solver_threads),
      hooks_(std::move(hooks)) {
  options_.Check();
}

InertialStagesStats InertialStages::stats() const {
  MutexLock lock(mutex_);
  return stats_;
}

void InertialStages::Step(const KeyFramePtr& kf) {
  bool initialized = false;
  bool ba1 = false;
  bool ba2 = false;
  double step_s = 0;  // the interval from the previous keyframe, if the body moved over it
  std::int64_t init_t_ns = 0;
  const InertialMappingOptions& o = options_;
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
  const bool mono = IsMonocular(sensor_);
  if (!initialized) {
    initializing_.store(true);
    if (Initialize(kf, o.init_gyro_prior,
                   mono ? o.init_accel_prior_mono : o.init_accel_prior_stereo, 0)) {
      motion_clock_.Restart();
    }
    initializing_.store(false);
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
  if (hooks_.calibration_running && hooks_.calibration_running()) return;
  auto mark = [&](bool second) {
    auto lock = MapEditor(atlas_).Write(MapEdit::kInertialInitialisation);
    if (kf->map() == nullptr) return;
    MapImuStatus& status = kf->map()->mutable_imu_status(lock);
    (second ? status.inertial_ba2_done : status.inertial_ba1_done) = true;
  };
  if (!ba1 && since > o.viba1_s) {
    initializing_.store(true);
    if (Initialize(kf, o.viba1_gyro_prior, o.viba1_accel_prior, 1)) mark(false);
    initializing_.store(false);
  } else if (ba1 && !ba2 && since > o.viba2_s) {
    initializing_.store(true);
    if (Initialize(kf, o.viba2_gyro_prior, o.viba2_accel_prior, 2)) mark(true);
    initializing_.store(false);
  } else if (ba2 && o.gravity_refinement) {
    RefineGravity(kf);
  }
}

void InertialStages::RefineGravity(const KeyFramePtr& kf) {
  const InertialMappingOptions& o = options_;
  InertialBundleOptions ba = o.local_ba;
  ba.iterations_first = o.gravity_refinement_iterations;
  ba.iterations_second = 0;
  ba.num_threads = solver_threads_;
  // A queued keyframe comes first (a monocular map gets its points only here); the next
  // keyframe tries again.
  if (hooks_.keyframe_queued && hooks_.keyframe_queued()) return;
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
  const InertialBundleResult result =
      SolveInertialBundle(problem->bundle, ba, hooks_.abort, hooks_.work);
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

bool InertialStages::Initialize(const KeyFramePtr& kf, double gyro_prior, double accel_prior,
                                int stage) {
  const bool refinement = stage > 0;
  const InertialMappingOptions& o = options_;
  const bool mono = IsMonocular(sensor_);
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
  FullBundleAdjustment(newest, gyro_prior, accel_prior);
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

void InertialStages::FullBundleAdjustment(const KeyFramePtr& kf, double gyro_prior,
                                          double accel_prior) {
  InertialBundleProblem problem;
  InertialBundleOptions ba = options_.local_ba;
  ba.iterations_first = options_.full_ba_iterations;
  ba.iterations_second = options_.full_ba_iterations;
  ba.num_threads = solver_threads_;
  {
    auto lock = MapReader(*atlas_).Lock();
    if (kf->IsBad() || kf->map() == nullptr) return;
    problem = CollectFullInertialBundle(kf.get(), ba);
  }
  if (problem.empty()) return;
  problem.shared_bias = true;
  problem.gyro_prior_information = gyro_prior;
  problem.accel_prior_information = accel_prior;
  const InertialBundleResult result = SolveInertialBundle(problem, ba, nullptr, hooks_.work);
  auto lock = MapEditor(atlas_).Write(MapEdit::kInertialInitialisation);
  Map* map = atlas_->FindMap(problem.visual.map_id);
  if (kf->map() == nullptr || map == nullptr) return;
  ApplyFullInertialBundle(lock, map, *kf, problem, result);
}

}  // namespace pkslam
