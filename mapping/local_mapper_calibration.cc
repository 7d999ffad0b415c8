// LocalMapper: online calibration (docs/calibration.md). A calibration bundle adjustment of the
// whole map when due, solved without the lock and applied like a global BA.
#include <fmt/format.h>

#include <chrono>

#include "core/util/error.h"
#include "core/util/log.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "mapping/calibration_apply.h"
#include "mapping/calibration_collect.h"
#include "mapping/local_mapper.h"

namespace pkslam {

void LocalMapper::RefineCalibration(const KeyFramePtr& kf) {
  const OnlineCalibrationOptions& o = options_.calibration;
  // A queued keyframe comes first; the next one tries again.
  if (HasQueued()) return;
  CalibrationBundleProblem problem;
  CalibrationRefinementStat stat;
  int change_index = 0;
  RigSetup setup;
  {
    auto lock = MapReader(*atlas_).Lock();
    if (kf->IsBad() || kf->map() == nullptr) return;
    const Map* map = kf->map();
    if (map != calibration_map_) {
      calibration_map_ = map;
      calibration_due_s_ = o.first_after_s;
    }
    const KeyFrame* origin = map->origin();
    if (origin == nullptr) return;
    stat.span_s = kf->t_s() - origin->t_s();
    if (stat.span_s < calibration_due_s_) return;
    // An inertial map is adjusted with its IMU once its first visual-inertial BA settled the
    // scale and gravity (ORB-SLAM3's VIBA1, about 5 s after the IMU initialisation).
    const bool inertial = IsInertial(rig_->sensor) && map->imu_status().inertial_ba1_done;
    if (IsInertial(rig_->sensor) && !inertial) return;
    CalibrationCollectOptions collect;
    collect.max_observations_per_keyframe = o.max_observations_per_keyframe;
    collect.gyro_scale_jacobians = o.gyro_scale;
    setup = atlas_->rig_setup();
    problem = CollectCalibrationBundle(kf.get(), inertial, setup, atlas_->calibration(),
                                       calibration_prior_, collect);
    change_index = map->change_index();
  }
  calibration_due_s_ = stat.span_s * o.growth;
  stat.t_ns = kf->t_ns();
  stat.keyframes = static_cast<int>(problem.bundle.visual.keyframes.size());
  stat.observations = static_cast<int>(problem.raw.size());
  stat.gates = DecideFreedom(problem, rig_->sensor, o);
  problem.free = stat.gates.free;
  const auto start = std::chrono::steady_clock::now();
  const auto finish = [&](const std::string& note) {
    stat.note = note;
    stat.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                  .count();
    MutexLock stats_lock(mutex_);
    stats_.calibration_refinements.push_back(stat);
  };
  if (!problem.free.Any() || problem.empty()) {
    stat.parameters = CalibrationParameters(problem.prior, problem.initial, problem.free,
                                            o.prior, problem.inertial);
    finish("nothing observable yet");
    return;
  }
  CalibrationBundleOptions ba;
  ba.iterations_first = o.iterations_first;
  ba.iterations_second = o.iterations_second;
  ba.num_threads = options_.ba.num_threads;
  ba.covariance = false;
  ba.min_iterations_before_abort = o.min_iterations;
  ba.prior = o.prior;
  const CalibrationBundleResult result = SolveCalibrationBundle(problem, ba, &abort_ba_, &work_);
  stat.iterations = result.bundle.visual.iterations;
  stat.initial_cost = result.bundle.visual.initial_cost;
  stat.final_cost = result.bundle.visual.final_cost;
  stat.parameters = result.parameters;
  if (result.bundle.visual.iterations == 0) {
    finish("interrupted before its first step");
    return;
  }
  if (const auto why = ImplausibleEstimate(problem, result.estimate, o, o.max_step_prior_sigmas)) {
    PKSLAM_LOG_WARN("calibration adjustment at t = {:.1f} s not applied: {}", stat.span_s, *why);
    finish("rejected: " + *why);
    return;
  }
  // The new rig (rectification maps) is built outside the lock.
  RigSetup next;
  try {
    next = BuildRig(result.estimate, rig_shape_);
  } catch (const OptionError& e) {
    finish(fmt::format("estimate rejected: {}", e.what()));
    return;
  }
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kCalibration);
    Map* map = kf->map();
    if (map == nullptr || kf->IsBad() || map->change_index() != change_index ||
        atlas_->rig_setup().rig != setup.rig) {
      // A loop correction, merge or another calibration moved the map meanwhile.
      lock.unlock();
      calibration_due_s_ = stat.span_s;  // try again with the next keyframe
      finish("the map moved meanwhile");
      return;
    }
    ApplyCalibration(atlas_, map, problem, result, next);
  }
  rig_ = next.rig;
  RefinePointsToCalibration(atlas_, problem.bundle.visual.map_id);
  stat.applied = true;
  finish("");
  PKSLAM_LOG_INFO(
      "calibration at t = {:.1f} s ({} keyframes, {} observations, {} iterations): time offset "
      "{:.3f} ms",
      stat.span_s, stat.keyframes, stat.observations, stat.iterations,
      result.estimate.time_offset_s * 1e3);
}

}  // namespace pkslam
