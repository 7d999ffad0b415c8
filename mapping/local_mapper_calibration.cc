// LocalMapper: online calibration (docs/calibration.md). A calibration bundle adjustment of the
// whole map when due: gathered in the keyframe step, solved without the lock inside the step or
// (OnlineCalibrationOptions::own_thread) in a thread of its own while local mapping goes on, and
// applied like a global BA. Under live emulation on the work clock the thread's result is
// applied by local mapping at the data time its work would have ended on the reference machine
// (ApplyDueCalibration), so where it lands does not depend on this machine's speed (offline
// runs repeated within 0.1 mm of ATE over three runs; the multithreaded solvers are not paced).
#include <fmt/format.h>

#include <chrono>
#include <exception>
#include <future>
#include <string>

#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/wall_time.h"
#include "map_model/estimation/calibration_apply.h"
#include "map_model/estimation/calibration_collect.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "mapping/local_mapper.h"

namespace pkslam {

void LocalMapper::RefineCalibration(const KeyFramePtr& kf) {
  const OnlineCalibrationOptions& o = options_.calibration;
  // A queued keyframe comes first; the next one tries again. So does an adjustment still solving
  // in its own thread.
  if (HasQueued() || CalibrationOutstanding()) return;
  JoinCalibrationThread();  // the previous adjustment has ended
  {
    MutexLock lock(mutex_);
    if (calibration_retry_s_) calibration_due_s_ = *calibration_retry_s_;
    calibration_retry_s_.reset();
  }
  CalibrationJob job;
  job.kf = kf;
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
    job.stat.span_s = kf->t_s() - origin->t_s();
    if (job.stat.span_s < calibration_due_s_) return;
    // An inertial map is adjusted with its IMU once its first visual-inertial BA settled the
    // scale and gravity (ORB-SLAM3's VIBA1, about 5 s after the IMU initialisation).
    const bool inertial = IsInertial(rig_->sensor) && map->imu_status().inertial_ba1_done;
    if (IsInertial(rig_->sensor) && !inertial) return;
    CalibrationCollectOptions collect;
    collect.max_observations_per_keyframe = o.max_observations_per_keyframe;
    collect.gyro_scale_jacobians = o.gyro_scale;
    job.setup = atlas_->rig_setup();
    job.problem = CollectCalibrationBundle(kf.get(), inertial, job.setup, atlas_->calibration(),
                                           calibration_prior_, collect);
    job.change_index = map->change_index();
  }
  calibration_due_s_ = job.stat.span_s * o.growth;
  job.stat.t_ns = kf->t_ns();
  job.stat.keyframes = static_cast<int>(job.problem.bundle.visual.keyframes.size());
  job.stat.observations = static_cast<int>(job.problem.raw.size());
  job.stat.gates = DecideFreedom(job.problem, rig_->sensor, o);
  job.problem.free = job.stat.gates.free;
  if (!o.own_thread || !thread_.joinable()) {
    // In the keyframe step: its work counts on local mapping's clock and a new keyframe
    // interrupts it (after `min_iterations`).
    if (auto solved = SolveCalibration(std::move(job), &abort_ba_, &work_)) {
      ApplySolvedCalibration(std::move(*solved));
    }
    return;
  }
  calibration_abort_.store(false);
  calibration_running_.store(true);
  if (!Paced()) {
    calibration_thread_ = std::thread([this, job = std::move(job)]() mutable {
      if (auto solved = SolveCalibration(std::move(job), &calibration_abort_, nullptr)) {
        ApplySolvedCalibration(std::move(*solved));
      }
      calibration_running_.store(false);
    });
    return;
  }
  {
    MutexLock lock(mutex_);
    calibration_start_ns_ = LiveReachedNs();
  }
  calibration_work_start_ = calibration_work_.Snapshot();
  calibration_pending_ = true;
  std::promise<std::optional<SolvedCalibration>> promise;
  calibration_solved_ = promise.get_future();
  calibration_thread_ = std::thread(
      [this, job = std::move(job), promise = std::move(promise)]() mutable {
        try {
          promise.set_value(SolveCalibration(std::move(job), &calibration_abort_,
                                             &calibration_work_));
        } catch (...) {
          promise.set_exception(std::current_exception());  // rethrown on the mapping thread
        }
        calibration_running_.store(false);
      });
}

bool LocalMapper::CalibrationOutstanding() const {
  return Paced() ? calibration_pending_ : calibration_running_.load();
}

void LocalMapper::ApplyDueCalibration() {
  if (!calibration_pending_) return;
  while (true) {
    std::int64_t reached = 0;
    {
      MutexLock lock(mutex_);
      if (stop_requested_ || finish_requested_ || reset_requested_) return;
      reached = LiveReachedNs();
    }
    // Read `done` before the work: once done, the count read after it is the final one.
    const bool done =
        calibration_solved_.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
    const std::int64_t due =
        calibration_start_ns_ +
        DataNs(kReferenceWork.Seconds(calibration_work_.Snapshot() - calibration_work_start_));
    if (due >= reached) return;  // not due yet: its work so far already reaches past now
    if (done) break;
    // Due by now on the reference machine, still solving on this one: wait for its work.
    calibration_solved_.wait_for(std::chrono::milliseconds(2));
  }
  calibration_pending_ = false;
  std::optional<SolvedCalibration> solved = calibration_solved_.get();
  JoinCalibrationThread();
  if (solved) ApplySolvedCalibration(std::move(*solved));
}

void LocalMapper::RecordCalibration(CalibrationRefinementStat stat, std::string note,
                                    std::chrono::steady_clock::time_point start) {
  stat.note = std::move(note);
  stat.ms = WallMsSince(start);
  MutexLock lock(mutex_);
  stats_.calibration_refinements.push_back(std::move(stat));
}

void LocalMapper::JoinCalibrationThread() {
  if (calibration_thread_.joinable()) calibration_thread_.join();
}

void LocalMapper::StopCalibrationThread() {
  calibration_abort_.store(true);
  JoinCalibrationThread();
  if (!calibration_pending_) return;
  calibration_pending_ = false;
  try {
    if (std::optional<SolvedCalibration> solved = calibration_solved_.get()) {
      RecordCalibration(std::move(solved->job.stat),
                        "not applied: the run ended or reset before it was due", solved->start);
    }
  } catch (const std::exception& e) {
    PKSLAM_LOG_WARN("calibration adjustment failed: {}", e.what());
  }
}

std::optional<LocalMapper::SolvedCalibration> LocalMapper::SolveCalibration(
    CalibrationJob job, const std::atomic<bool>* abort, WorkMeter* work) {
  const OnlineCalibrationOptions& o = options_.calibration;
  CalibrationBundleProblem& problem = job.problem;
  CalibrationRefinementStat& stat = job.stat;
  const auto start = std::chrono::steady_clock::now();
  const auto finish = [&](const std::string& note) -> std::optional<SolvedCalibration> {
    RecordCalibration(stat, note, start);
    return std::nullopt;
  };
  if (!problem.free.Any() || problem.empty()) {
    stat.parameters = CalibrationParameters(problem.prior, problem.initial, problem.free,
                                            o.prior, problem.inertial);
    return finish("nothing observable yet");
  }
  CalibrationBundleOptions ba;
  ba.iterations_first = o.iterations_first;
  ba.iterations_second = o.iterations_second;
  ba.num_threads = options_.ba.num_threads;
  ba.covariance = false;
  ba.min_iterations_before_abort = o.min_iterations;
  ba.prior = o.prior;
  CalibrationBundleResult result = SolveCalibrationBundle(problem, ba, abort, work);
  stat.iterations = result.bundle.visual.iterations;
  stat.initial_cost = result.bundle.visual.initial_cost;
  stat.final_cost = result.bundle.visual.final_cost;
  stat.parameters = result.parameters;
  if (result.bundle.visual.iterations == 0) {
    return finish("interrupted before its first step");
  }
  if (const auto why = ImplausibleEstimate(problem, result.estimate, o, o.max_step_prior_sigmas)) {
    PKSLAM_LOG_WARN("calibration adjustment at t = {:.1f} s not applied: {}", stat.span_s, *why);
    return finish("rejected: " + *why);
  }
  // The new rig (rectification maps) is built outside the lock.
  RigSetup next;
  try {
    next = BuildRig(result.estimate, rig_shape_);
  } catch (const OptionError& e) {
    return finish(fmt::format("estimate rejected: {}", e.what()));
  }
  return SolvedCalibration{std::move(job), std::move(result), std::move(next), start};
}

void LocalMapper::ApplySolvedCalibration(SolvedCalibration solved) {
  const CalibrationBundleProblem& problem = solved.job.problem;
  CalibrationRefinementStat& stat = solved.job.stat;
  const KeyFramePtr& kf = solved.job.kf;
  const CalibrationBundleResult& result = solved.result;
  const RigSetup& next = solved.next;
  const CalibrationJob& job = solved.job;
  const auto finish = [&](const std::string& note) { RecordCalibration(stat, note, solved.start); };
  std::string note;
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kCalibration);
    Map* map = kf->map();
    if (map == nullptr || kf->IsBad() || map->id() != problem.bundle.visual.map_id ||
        atlas_->rig_setup().rig != job.setup.rig) {
      // A merge, reset or another calibration replaced the map or the rig meanwhile.
      lock.unlock();
      {
        MutexLock retry_lock(mutex_);
        calibration_retry_s_ = stat.span_s;  // try again with the next keyframe
      }
      finish("the map moved meanwhile");
      return;
    }
    if (map->change_index() != job.change_index) {
      // A loop correction or global BA moved the map's states meanwhile: writing the
      // adjustment's poses back would undo it. The calibration does not depend on where the
      // map lies, so the map moves to it with the bodies where they are now, as after the
      // final adjustment (a solve thrown away here was redone from the next keyframe on: 2-3
      // of 9 adjustments of a V1_02 replay with loops, 2026-11-29).
      MoveToCalibration(lock, atlas_, result.estimate, next);
      note = "calibration only: the map moved meanwhile";
    } else {
      ApplyCalibration(lock, atlas_, map, problem, result, next);
    }
  }
  RefinePointsToCalibration(atlas_, problem.bundle.visual.map_id);
  stat.applied = true;
  finish(note);
  PKSLAM_LOG_INFO(
      "calibration at t = {:.1f} s ({} keyframes, {} observations, {} iterations): time offset "
      "{:.3f} ms",
      stat.span_s, stat.keyframes, stat.observations, stat.iterations,
      result.estimate.time_offset_s * 1e3);
}

}  // namespace pkslam
