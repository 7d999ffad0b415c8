// LocalMapper: local inertial BA (the whole-map stages are mapping/inertial_stages.h), and the
// inertial options' check (mapping/inertial_mapping.h).
#include <mutex>
#include <shared_mutex>

#include "core/util/error.h"
#include "core/util/log.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
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
  MutexLock stats_lock(mutex_);
  if (result.visual.aborted) ++stats_.ba_aborted;
  ++(problem.anchor_prior ? stats_.inertial_ba_with_prior : stats_.inertial_ba_fixed_anchor);
  return true;
}

}  // namespace pkslam
