// Online calibration's policy (docs/calibration.md): when local mapping runs a calibration
// bundle adjustment (calibration_collect.h -> estimators/calibration -> calibration_apply.h),
// which parameters the motion so far makes observable, and what each run leaves in the stats.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/sensor/sensor.h"
#include "estimators/calibration/calibration_bundle.h"

namespace pkslam {

struct OnlineCalibrationOptions {
  // --calibrate online (true) | off.
  bool enabled = false;
  CalibrationPriorOptions prior;
  // Observations per keyframe in an adjustment (evenly over the image; 0: all).
  int max_observations_per_keyframe = 150;
  // Solver iterations of the robust pass and of the refinement without outliers; a new keyframe
  // interrupts an adjustment only after `min_iterations` (on a busy map every adjustment would
  // be interrupted before its first step: V1_02 replay, 2 of 6).
  int iterations_first = 8;
  int iterations_second = 4;
  int min_iterations = 3;
  // The first adjustment once the map spans this much data time (s); the next whenever the span
  // grew by `growth` (8, 12, 18, 27, ... s), so a flight of T seconds gets about log(T/8)/log(1.5)
  // of them, most of them early, when the estimate moves most.
  double first_after_s = 8.0;
  double growth = 1.5;
  // The final whole-map adjustment when the run ends (its sigmas are what the run reports):
  // observations per keyframe (0: all; `pkslam calibrate`) and iterations.
  int final_max_observations_per_keyframe = 150;
  int final_iterations_first = 8;
  int final_iterations_second = 4;
  // Solve each adjustment in a thread of its own while local mapping goes on, as the global BA
  // after a loop runs beside it: inside the keyframe step an adjustment held local mapping for
  // 0.1-2.5 s, and tracking, which cannot insert keyframes meanwhile, waited for it in the live
  // emulation (docs/calibration.md, "Cost"). Its result is applied (its calibration only if a
  // loop correction moved the map meanwhile, nothing if a merge replaced it); keyframes created
  // meanwhile follow their parents. Under the work-clock live emulation local mapping applies
  // it where its counted work makes it due, so offline runs repeat. Runs set it from
  // SystemOptions::calibration_thread: off in lock-step, where each keyframe's step ends it.
  bool own_thread = true;
  // Too few keyframes tell too little.
  int min_keyframes = 10;
  // Estimate the camera-IMU translation (the lever arm) too. Off by default: on the realistic
  // replays its estimate moved away from the truth (the IMU errors the model leaves out, scale
  // factors, axis misalignment and g-sensitivity, bias it) and freeing it raised stereo-inertial
  // ATE (docs/calibration.md, "Parameters left at the file's value").
  bool imu_translation = false;
  // Estimate the intrinsics of a monocular rig too. Off by default: with one camera the focal
  // length trades against the map's depth, held only by the IMU's scale, and on the V2_01 replay
  // freeing them moved cam0's fx and cx further from the truth (0.6 -> 0.9-1.4 px) and raised
  // mono-inertial ATE (docs/calibration.md, "Parameters left at the file's value").
  bool monocular_intrinsics = false;
  // Estimate the gyroscope's per-axis scale factor (inertial rigs). On by default: an
  // unmodelled scale error of the gyro is absorbed by the focal length (calibration_bundle.h).
  bool gyro_scale = true;
  // Estimate the accelerometer's axis errors (scale factors and misalignment; inertial rigs).
  // On by default: an unmodelled misalignment tilts the gravity the accelerometer sees, and the
  // camera-IMU rotation takes the tilt (calibration_bundle.h).
  bool accel_axes = true;
  // Estimate the accelerometer's per-axis scale factors (E's diagonal) too. Off by default: they
  // are seen only through gravity's magnitude on the axes the body tilts about and through the
  // motion's accelerations, which trade against the map's scale; on the V1_01 replay with exact
  // files, freeing them moved one 0.68% from the truth, the map's scale +0.30% and the
  // stereo-inertial ATE from 4.5 (off) to 6.6 mm (docs/calibration.md).
  bool accel_scale = false;
  // Estimate the accelerometer's axis errors on a monocular-inertial rig too. Off by default:
  // with one camera the map's scale is the IMU's alone, and on the V1_02 replay the free
  // misalignment went 0.3 deg from the truth (3 prior sigmas), the map 2.2% too small and
  // mono-inertial ATE from 7.9 to 40.9 mm (docs/calibration.md).
  bool monocular_accel_axes = false;
  // Observability gates (DecideFreedom). Camera-IMU rotation: the angular rate about the
  // keyframes' second-most-excited axis (rms, rad/s): rotation about a single axis leaves the
  // rotation about it unobservable. Camera-IMU translation (a lever arm seen only through
  // rotation): the same rate, higher.
  double min_rotation_rate = 0.05;
  double min_lever_rotation_rate = 0.1;
  // Time offset: the image must move, through rotation (median |omega|, rad/s) or translation
  // (median speed, m/s).
  double min_turn_rate = 0.05;
  double min_speed = 0.1;
  // Intrinsics: observations in at least this many cells of a 4x4 grid over the image (each with
  // at least `min_cell_observations`).
  int min_covered_cells = 12;
  int min_cell_observations = 10;
  // Stereo extrinsic: at least this many stereo matches.
  int min_stereo_observations = 500;
  // An adjustment is not applied when a parameter ends more than `max_prior_sigmas` of its
  // prior's sigmas from the file's value, or moved more than `max_step_prior_sigmas` of them in
  // this one adjustment: a diverged solve (a monocular map that lost its scale pulled cam0's fx
  // 34 px, 17 sigma, in one step on a V2_01 replay), not a calibration. A gross file error (2 deg,
  // 11 ms, 5 px: 4-6 sigma), corrected in one step, stays within both.
  double max_prior_sigmas = 10.0;
  double max_step_prior_sigmas = 8.0;
  // The final whole-map adjustment refines what mapping converged to; a step beyond this many
  // prior sigmas from it is drift along a weakly observed direction (mono-inertial V2_01 replay:
  // cam0's fx 9 px in the final adjustment after holding within 0.5 px over 6 adjustments), and
  // the run keeps mapping's estimate.
  double final_max_step_prior_sigmas = 3.0;

  void Check() const;
};

// The parameter groups a refinement frees, and why the others stay frozen.
struct CalibrationGates {
  CalibrationFreedom free;
  // group ("intrinsics", "stereo", "imu_rotation", "imu_translation", "time_offset",
  // "gyro_scale", "accel_axes", "accel_scale") -> reason
  std::map<std::string, std::string> frozen;
  // The measured motion and coverage the gates compared.
  double second_axis_rate = 0;  // rad/s
  double median_turn_rate = 0;  // rad/s
  double median_speed = 0;      // m/s
  int covered_cells = 0;
  int stereo_observations = 0;
};

// Which parameters `problem` (collected from a map of `sensor`) can estimate. Monocular without
// an IMU and RGB-D freeze everything: a monocular map has no metric scale to hold the intrinsics
// against, and the RGB-D pipeline takes the depth image's registration as given.
CalibrationGates DecideFreedom(const CalibrationBundleProblem& problem, Sensor sensor,
                               const OnlineCalibrationOptions& options);

// Why the estimate of an adjustment that started from `problem.initial` must not be applied:
// more than options.max_prior_sigmas from the file, or more than `max_step_prior_sigmas` from
// where it started (mapping's adjustments: options.max_step_prior_sigmas; the final one:
// options.final_max_step_prior_sigmas), or nullopt.
std::optional<std::string> ImplausibleEstimate(const CalibrationBundleProblem& problem,
                                               const RigCalibration& estimate,
                                               const OnlineCalibrationOptions& options,
                                               double max_step_prior_sigmas);

// One calibration adjustment of a run (stats.json "calibration.history").
struct CalibrationRefinementStat {
  std::int64_t t_ns = 0;  // the keyframe that triggered it
  double span_s = 0;      // data time the map spanned
  int keyframes = 0;
  int observations = 0;
  int iterations = 0;
  double initial_cost = 0;
  double final_cost = 0;
  double ms = 0;
  bool applied = false;
  std::string note;  // why it was not applied
  CalibrationGates gates;
  std::vector<CalibrationParameter> parameters;  // the estimate it ended with
};

}  // namespace pkslam
