// Online calibration's schedule and thread. Under live emulation on the work clock the thread's
// result is applied by local mapping at the data time its work would have ended on the
// reference machine (ApplyDue), so where it lands does not depend on this machine's speed
// (offline runs repeated within 0.1 mm of ATE over three runs; the multithreaded solvers are
// not paced).
#include "mapping/online_calibrator.h"

#include <fmt/format.h>

#include <exception>
#include <utility>

#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/wall_time.h"
#include "map_model/estimation/calibration_apply.h"
#include "map_model/estimation/calibration_collect.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"

namespace pkslam {

OnlineCalibrator::OnlineCalibrator(Atlas* atlas, Sensor sensor, OnlineCalibrationOptions options,
                                   int solver_threads)
    : atlas_(atlas),
      sensor_(sensor),
      options_(std::move(options)),
      solver_threads_(solver_threads) {
  options_.Check();
}

OnlineCalibrator::~OnlineCalibrator() { Stop(); }

void OnlineCalibrator::SetPrior(RigCalibration file, RigShape shape) {
  prior_ = std::move(file);
  shape_ = std::move(shape);
}

void OnlineCalibrator::SetPacing(CalibrationPacing pacing) {
  PKSLAM_CHECK(!pacing.paced || (pacing.position && pacing.data_ns),
               "paced calibration needs local mapping's data clock");
  pacing_ = std::move(pacing);
}

void OnlineCalibrator::Step(const KeyFramePtr& kf, bool keyframe_queued, bool in_step,
                            const std::atomic<bool>* step_abort, WorkMeter* step_work) {
  // A queued keyframe comes first; the next one tries again. So does an adjustment still solving
  // in its own thread.
  if (keyframe_queued || Outstanding()) return;
  Join();  // the previous adjustment has ended
  std::optional<Job> job = Gather(kf);
  if (!job) return;
  if (in_step) {
    // Its work counts on local mapping's clock and a new keyframe interrupts it (after
    // `min_iterations`).
    if (auto solved = Solve(std::move(*job), step_abort, step_work)) Apply(std::move(*solved));
    return;
  }
  StartThread(std::move(*job));
}

std::optional<OnlineCalibrator::Job> OnlineCalibrator::Gather(const KeyFramePtr& kf) {
  {
    MutexLock lock(mutex_);
    if (retry_s_) due_s_ = *retry_s_;
    retry_s_.reset();
  }
  Job job;
  job.kf = kf;
  {
    auto lock = MapReader(*atlas_).Lock();
    if (kf->IsBad() || kf->map() == nullptr) return std::nullopt;
    const Map* map = kf->map();
    if (map != map_) {
      map_ = map;
      due_s_ = options_.first_after_s;
    }
    const KeyFrame* origin = map->origin();
    if (origin == nullptr) return std::nullopt;
    job.stat.span_s = kf->t_s() - origin->t_s();
    if (job.stat.span_s < due_s_) return std::nullopt;
    // An inertial map is adjusted with its IMU once its first visual-inertial BA settled the
    // scale and gravity (ORB-SLAM3's VIBA1, about 5 s after the IMU initialisation).
    const bool inertial = IsInertial(sensor_) && map->imu_status().inertial_ba1_done;
    if (IsInertial(sensor_) && !inertial) return std::nullopt;
    CalibrationCollectOptions collect;
    collect.max_observations_per_keyframe = options_.max_observations_per_keyframe;
    collect.imu_axes_jacobians = options_.gyro_scale || options_.accel_axes;
    job.setup = atlas_->rig_setup();
    job.problem = CollectCalibrationBundle(lock, kf.get(), inertial, job.setup,
                                           atlas_->calibration(), prior_, collect);
    job.change_index = map->change_index();
  }
  due_s_ = job.stat.span_s * options_.growth;
  job.stat.t_ns = kf->t_ns();
  job.stat.keyframes = static_cast<int>(job.problem.bundle.visual.keyframes.size());
  job.stat.observations = static_cast<int>(job.problem.raw.size());
  job.stat.gates = DecideFreedom(job.problem, sensor_, options_);
  job.problem.free = job.stat.gates.free;
  return job;
}

void OnlineCalibrator::StartThread(Job job) {
  abort_.store(false);
  running_.store(true);
  if (!pacing_.paced) {
    thread_ = std::thread([this, job = std::move(job)]() mutable {
      if (auto solved = Solve(std::move(job), &abort_, nullptr)) Apply(std::move(*solved));
      running_.store(false);
    });
    return;
  }
  start_ns_ = pacing_.position().reached_ns;
  work_start_ = work_.Snapshot();
  pending_ = true;
  std::promise<std::optional<Solved>> promise;
  solved_ = promise.get_future();
  thread_ = std::thread([this, job = std::move(job), promise = std::move(promise)]() mutable {
    try {
      promise.set_value(Solve(std::move(job), &abort_, &work_));
    } catch (...) {
      promise.set_exception(std::current_exception());  // rethrown on the mapping thread
    }
    running_.store(false);
  });
}

bool OnlineCalibrator::Outstanding() const { return pacing_.paced ? pending_ : running_.load(); }

void OnlineCalibrator::ApplyDue() {
  if (!pending_) return;
  while (true) {
    const LiveDataPosition now = pacing_.position();
    if (now.stopping) return;
    // Read `done` before the work: once done, the count read after it is the final one.
    const bool done = solved_.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
    const std::int64_t due = start_ns_ + pacing_.data_ns(work_.Snapshot() - work_start_);
    if (due >= now.reached_ns) return;  // not due yet: its work so far already reaches past now
    if (done) break;
    // Due by now on the reference machine, still solving on this one: wait for its work.
    solved_.wait_for(std::chrono::milliseconds(2));
  }
  pending_ = false;
  std::optional<Solved> solved = solved_.get();
  Join();
  if (solved) Apply(std::move(*solved));
}

void OnlineCalibrator::Record(CalibrationRefinementStat stat, std::string note,
                              std::chrono::steady_clock::time_point start) {
  stat.note = std::move(note);
  stat.ms = WallMsSince(start);
  MutexLock lock(mutex_);
  history_.push_back(std::move(stat));
}

std::vector<CalibrationRefinementStat> OnlineCalibrator::history() const {
  MutexLock lock(mutex_);
  return history_;
}

void OnlineCalibrator::Join() {
  if (thread_.joinable()) thread_.join();
}

void OnlineCalibrator::Stop() {
  abort_.store(true);
  Join();
  if (!pending_) return;
  pending_ = false;
  try {
    if (std::optional<Solved> solved = solved_.get()) {
      Record(std::move(solved->job.stat), "not applied: the run ended or reset before it was due",
             solved->start);
    }
  } catch (const std::exception& e) {
    PKSLAM_LOG_WARN("calibration adjustment failed: {}", e.what());
  }
}

std::optional<OnlineCalibrator::Solved> OnlineCalibrator::Solve(Job job,
                                                                const std::atomic<bool>* abort,
                                                                WorkMeter* work) {
  CalibrationBundleProblem& problem = job.problem;
  CalibrationRefinementStat& stat = job.stat;
  const auto start = std::chrono::steady_clock::now();
  const auto finish = [&](const std::string& note) -> std::optional<Solved> {
    Record(stat, note, start);
    return std::nullopt;
  };
  if (!problem.free.Any() || problem.empty()) {
    stat.parameters = CalibrationParameters(problem.prior, problem.initial, problem.free,
                                            options_.prior, problem.inertial);
    return finish("nothing observable yet");
  }
  CalibrationBundleOptions ba;
  ba.iterations_first = options_.iterations_first;
  ba.iterations_second = options_.iterations_second;
  ba.num_threads = solver_threads_;
  ba.covariance = false;
  ba.min_iterations_before_abort = options_.min_iterations;
  ba.prior = options_.prior;
  CalibrationBundleResult result = SolveCalibrationBundle(problem, ba, abort, work);
  stat.iterations = result.bundle.visual.iterations;
  stat.initial_cost = result.bundle.visual.initial_cost;
  stat.final_cost = result.bundle.visual.final_cost;
  stat.parameters = result.parameters;
  if (result.bundle.visual.iterations == 0) return finish("interrupted before its first step");
  if (const auto why =
          ImplausibleEstimate(problem, result.estimate, options_, options_.max_step_prior_sigmas)) {
    PKSLAM_LOG_WARN("calibration adjustment at t = {:.1f} s not applied: {}", stat.span_s, *why);
    return finish("rejected: " + *why);
  }
  // The new rig (rectification maps) is built outside the lock.
  RigSetup next;
  try {
    next = BuildRig(result.estimate, shape_);
  } catch (const OptionError& e) {
    return finish(fmt::format("estimate rejected: {}", e.what()));
  }
  return Solved{std::move(job), std::move(result), std::move(next), start};
}

void OnlineCalibrator::Apply(Solved solved) {
  const Job& job = solved.job;
  const CalibrationBundleProblem& problem = job.problem;
  CalibrationRefinementStat& stat = solved.job.stat;
  const CalibrationBundleResult& result = solved.result;
  std::string note;
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kCalibration);
    Map* map = job.kf->map();
    if (map == nullptr || job.kf->IsBad() || map->id() != problem.bundle.visual.map_id ||
        atlas_->rig_setup().rig != job.setup.rig) {
      // A merge, reset or another calibration replaced the map or the rig meanwhile.
      lock.unlock();
      {
        MutexLock retry_lock(mutex_);
        retry_s_ = stat.span_s;  // try again with the next keyframe
      }
      Record(stat, "the map moved meanwhile", solved.start);
      return;
    }
    if (map->change_index() != job.change_index) {
      // A loop correction or global BA moved the map's states meanwhile: writing the
      // adjustment's poses back would undo it. The calibration does not depend on where the
      // map lies, so the map moves to it with the bodies where they are now, as after the
      // final adjustment (a solve thrown away here was redone from the next keyframe on: 2-3
      // of 9 adjustments of a V1_02 replay with loops, 2026-11-29).
      MoveToCalibration(lock, atlas_, result.estimate, solved.next);
      note = "calibration only: the map moved meanwhile";
    } else {
      ApplyCalibration(lock, atlas_, map, problem, result, solved.next);
    }
  }
  RefinePointsToCalibration(atlas_, problem.bundle.visual.map_id);
  stat.applied = true;
  Record(stat, note, solved.start);
  PKSLAM_LOG_INFO(
      "calibration at t = {:.1f} s ({} keyframes, {} observations, {} iterations): time offset "
      "{:.3f} ms",
      stat.span_s, stat.keyframes, stat.observations, stat.iterations,
      result.estimate.time_offset_s * 1e3);
}

}  // namespace pkslam
