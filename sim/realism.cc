#include "sim/realism.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <map>

#include "core/util/error.h"

namespace pkslam::sim {

RealismPreset ParseRealismPreset(const std::string& name) {
  if (name == "ideal") return RealismPreset::kIdeal;
  if (name == "euroc") return RealismPreset::kEuroc;
  throw OptionError("--realism must be ideal or euroc, got '" + name + "'");
}

std::string RealismPresetName(RealismPreset preset) {
  return preset == RealismPreset::kEuroc ? "euroc" : "ideal";
}

RealismSource ParseRealismSource(const std::string& name) {
  for (RealismSource s : kRealismSources) {
    if (RealismSourceName(s) == name) return s;
  }
  throw OptionError(
      "realism source must be appearance, calibration, timing, imu, motion or ground-truth, "
      "got '" +
      name + "'");
}

std::string RealismSourceName(RealismSource source) {
  switch (source) {
    case RealismSource::kAppearance:
      return "appearance";
    case RealismSource::kCalibration:
      return "calibration";
    case RealismSource::kTiming:
      return "timing";
    case RealismSource::kImu:
      return "imu";
    case RealismSource::kMotion:
      return "motion";
    case RealismSource::kGroundTruth:
      return "ground-truth";
  }
  return "?";
}

void CalibrationErrorOptions::Check() const {
  PKSLAM_CHECK_OPTION(focal_px >= 0 && focal_px <= 20, "calibration.focal_px", "{}", focal_px);
  PKSLAM_CHECK_OPTION(principal_point_px >= 0 && principal_point_px <= 20,
                      "calibration.principal_point_px", "{}", principal_point_px);
  PKSLAM_CHECK_OPTION(k1 >= 0 && k1 <= 0.1, "calibration.k1", "{}", k1);
  PKSLAM_CHECK_OPTION(k2 >= 0 && k2 <= 0.1, "calibration.k2", "{}", k2);
  PKSLAM_CHECK_OPTION(tangential >= 0 && tangential <= 0.01, "calibration.tangential", "{}",
                      tangential);
  PKSLAM_CHECK_OPTION(per_camera_fraction >= 0 && per_camera_fraction <= 2,
                      "calibration.per_camera_fraction", "{}", per_camera_fraction);
  PKSLAM_CHECK_OPTION(stereo_rotation_deg >= 0 && stereo_rotation_deg <= 5,
                      "calibration.stereo_rotation_deg", "{}", stereo_rotation_deg);
  PKSLAM_CHECK_OPTION(stereo_translation_mm >= 0 && stereo_translation_mm <= 50,
                      "calibration.stereo_translation_mm", "{}", stereo_translation_mm);
  PKSLAM_CHECK_OPTION(imu_rotation_deg >= 0 && imu_rotation_deg <= 5,
                      "calibration.imu_rotation_deg", "{}", imu_rotation_deg);
  PKSLAM_CHECK_OPTION(imu_translation_mm >= 0 && imu_translation_mm <= 100,
                      "calibration.imu_translation_mm", "{}", imu_translation_mm);
}

void TimingErrorOptions::Check() const {
  PKSLAM_CHECK_OPTION(std::abs(camera_imu_offset_ms) <= 100.0, "timing.camera_imu_offset_ms", "{}",
                      camera_imu_offset_ms);
  PKSLAM_CHECK_OPTION(jitter_ms >= 0 && jitter_ms <= 10.0, "timing.jitter_ms", "{}", jitter_ms);
}

void ImuErrorOptions::Check() const {
  PKSLAM_CHECK_OPTION(gyro_scale_pct >= 0 && gyro_scale_pct <= 5, "imu.gyro_scale_pct", "{}",
                      gyro_scale_pct);
  PKSLAM_CHECK_OPTION(accel_scale_pct >= 0 && accel_scale_pct <= 5, "imu.accel_scale_pct", "{}",
                      accel_scale_pct);
  PKSLAM_CHECK_OPTION(gyro_misalignment_deg >= 0 && gyro_misalignment_deg <= 2,
                      "imu.gyro_misalignment_deg", "{}", gyro_misalignment_deg);
  PKSLAM_CHECK_OPTION(accel_misalignment_deg >= 0 && accel_misalignment_deg <= 2,
                      "imu.accel_misalignment_deg", "{}", accel_misalignment_deg);
  PKSLAM_CHECK_OPTION(gyro_g_sensitivity_dps_per_g >= 0 && gyro_g_sensitivity_dps_per_g <= 1,
                      "imu.gyro_g_sensitivity_dps_per_g", "{}", gyro_g_sensitivity_dps_per_g);
  PKSLAM_CHECK_OPTION(gyro_bias_rad_s >= 0 && gyro_bias_rad_s <= 0.5, "imu.gyro_bias_rad_s", "{}",
                      gyro_bias_rad_s);
  PKSLAM_CHECK_OPTION(accel_bias_m_s2 >= 0 && accel_bias_m_s2 <= 2, "imu.accel_bias_m_s2", "{}",
                      accel_bias_m_s2);
  PKSLAM_CHECK_OPTION(gyro_quantum_rad_s >= 0 && gyro_quantum_rad_s <= 0.01,
                      "imu.gyro_quantum_rad_s", "{}", gyro_quantum_rad_s);
  PKSLAM_CHECK_OPTION(accel_quantum_m_s2 >= 0 && accel_quantum_m_s2 <= 0.1,
                      "imu.accel_quantum_m_s2", "{}", accel_quantum_m_s2);
}

void MotionRealismOptions::Check() const {
  PKSLAM_CHECK_OPTION(position_knot_s >= 0.005 && position_knot_s <= 1.0, "motion.position_knot_s",
                      "{}", position_knot_s);
  PKSLAM_CHECK_OPTION(rotation_knot_s >= 0.005 && rotation_knot_s <= 1.0, "motion.rotation_knot_s",
                      "{}", rotation_knot_s);
  PKSLAM_CHECK_OPTION(vibration_scale >= 0 && vibration_scale <= 10, "motion.vibration_scale", "{}",
                      vibration_scale);
}

void GroundTruthErrorOptions::Check() const {
  PKSLAM_CHECK_OPTION(position_noise_mm >= 0 && position_noise_mm <= 100,
                      "ground_truth.position_noise_mm", "{}", position_noise_mm);
  PKSLAM_CHECK_OPTION(rotation_noise_deg >= 0 && rotation_noise_deg <= 10,
                      "ground_truth.rotation_noise_deg", "{}", rotation_noise_deg);
  PKSLAM_CHECK_OPTION(std::abs(time_offset_ms) <= 1000.0, "ground_truth.time_offset_ms", "{}",
                      time_offset_ms);
}

void AppearanceOptions::Check() const {
  PKSLAM_CHECK_OPTION(!vicon_scene.empty() && !machine_hall_scene.empty(), "appearance scenes",
                      "{}", "must be named");
  PKSLAM_CHECK_OPTION(max_exposure_ms >= 0 && max_exposure_ms < 50, "appearance.max_exposure_ms",
                      "{}", max_exposure_ms);
  PKSLAM_CHECK_OPTION(gain_flicker_percent >= 0 && gain_flicker_percent < 50 &&
                          cam1_gain_flicker_percent >= 0 && cam1_gain_flicker_percent < 50,
                      "appearance.gain_flicker_percent", "{} {}", gain_flicker_percent,
                      cam1_gain_flicker_percent);
  PKSLAM_CHECK_OPTION(veiling_glare_percent >= 0 && veiling_glare_percent < 50,
                      "appearance.veiling_glare_percent", "{}", veiling_glare_percent);
}

void RealismOptions::Check() const {
  calibration.Check();
  timing.Check();
  imu.Check();
  motion.Check();
  ground_truth.Check();
  appearance.Check();
}

RealismOptions MakeRealism(RealismPreset preset) {
  RealismOptions r;
  r.preset = preset;
  if (preset == RealismPreset::kIdeal) return r;  // every source off, every size zero
  r.enabled.fill(true);
  // Sizes: docs/realism.md has each with its documented range and reference; the values sit
  // inside those ranges (chosen with the ORB-SLAM3 peer on bench/suites/realism.yaml).
  CalibrationErrorOptions& c = r.calibration;
  c.focal_px = 0.5;
  c.principal_point_px = 0.75;
  c.k1 = 0.0015;
  c.k2 = 0.0015;
  c.tangential = 2e-4;
  c.per_camera_fraction = 0.2;
  c.stereo_rotation_deg = 0.014;
  c.stereo_translation_mm = 0.1;
  c.imu_rotation_deg = 0.15;
  c.imu_translation_mm = 3.0;
  r.timing.camera_imu_offset_ms = 1.0;
  r.timing.jitter_ms = 0.02;
  ImuErrorOptions& i = r.imu;
  i.gyro_scale_pct = 0.2;
  i.accel_scale_pct = 0.3;
  i.gyro_misalignment_deg = 0.03;
  i.accel_misalignment_deg = 0.03;
  i.gyro_g_sensitivity_dps_per_g = 0.01;
  i.gyro_bias_rad_s = 0.03;
  i.accel_bias_m_s2 = 0.08;
  i.gyro_quantum_rad_s = 0.04 * M_PI / 180.0;  // VI-Sensor driver: 0.04 deg/s per LSB
  i.accel_quantum_m_s2 = 9.81 / 1200.0;        // VI-Sensor driver: 1/1200 g per LSB
  MotionRealismOptions& m = r.motion;
  m.position_knot_s = 0.02;
  m.rotation_knot_s = 0.02;
  m.position_cutoff_hz = 6.0;
  m.rotation_cutoff_hz = 6.0;
  m.vibration = true;
  m.vibration_scale = 1.0;
  r.ground_truth.position_noise_mm = 0.5;
  r.ground_truth.rotation_noise_deg = 0.05;
  r.ground_truth.time_offset_ms = 2.25;
  AppearanceOptions& a = r.appearance;
  a.vicon_scene = "euroc_vicon_room";
  a.machine_hall_scene = "euroc_machine_hall";
  a.read_noise_dn = 0.43;
  a.shot_noise_gain = 0.012;
  a.blur_sigma_px = 0.7;
  a.vignetting = 0.4;
  a.target_brightness = 0.57;
  a.cam1_relative_gain = 0.84;
  a.exposure_adapt = 0.3;
  a.max_exposure_ms = 10.0;
  a.exposure_at_unit_gain_ms = 2.0;
  a.gain_flicker_percent = 0.20;
  a.cam1_gain_flicker_percent = 0.43;
  return r;
}

namespace {

// Every size with its name, unit, documented range and reference (docs/realism.md expands the
// references). One table serves the setter and the report.
struct ParameterRow {
  RealismSource source;
  const char* name;
  std::function<double&(RealismOptions&)> field;
  const char* unit;
  const char* range;
  const char* reference;
};

const std::vector<ParameterRow>& ParameterTable() {
  using S = RealismSource;
  static const std::vector<ParameterRow> kTable = {
      {S::kAppearance, "appearance.read_noise_dn",
       [](RealismOptions& r) -> double& { return r.appearance.read_noise_dn; }, "DN", "measured",
       "temporal noise of the 95 real static V1_01 pairs (evaluation/studies/realism/"
       "sensor_noise.py)"},
      {S::kAppearance, "appearance.shot_noise_gain",
       [](RealismOptions& r) -> double& { return r.appearance.shot_noise_gain; }, "DN", "measured",
       "same fit: variance = read^2 + gain * level"},
      {S::kAppearance, "appearance.blur_sigma_px",
       [](RealismOptions& r) -> double& { return r.appearance.blur_sigma_px; }, "px", "measured",
       "edge spread of the real static frames (sensor_noise.py)"},
      {S::kAppearance, "appearance.cam1_relative_gain",
       [](RealismOptions& r) -> double& { return r.appearance.cam1_relative_gain; }, "x",
       "measured", "cam1 / cam0 level at the same scene points of the real static pairs"},
      {S::kAppearance, "appearance.vignetting",
       [](RealismOptions& r) -> double& { return r.appearance.vignetting; }, "at 45 deg",
       "0.14-0.43",
       "Basalt's EuRoC vignette (0.72 at 500 px); stereo-matched real pairs: 0.59 in "
       "the corners (sensor_noise.py)"},
      {S::kAppearance, "appearance.target_brightness",
       [](RealismOptions& r) -> double& { return r.appearance.target_brightness; }, "of 255",
       "measured", "mean level of the real static frames, window included (145.6 DN)"},
      {S::kAppearance, "appearance.max_exposure_ms",
       [](RealismOptions& r) -> double& { return r.appearance.max_exposure_ms; }, "ms", "3-16",
       "VI-Sensor driver shutter limit 100-500 rows (libvisensor, visensor_node)"},
      {S::kAppearance, "appearance.gain_flicker_percent",
       [](RealismOptions& r) -> double& { return r.appearance.gain_flicker_percent; }, "%",
       "measured",
       "cam0's frame-to-frame gain change (std) on the real static frames (sensor_noise.py)"},
      {S::kAppearance, "appearance.cam1_gain_flicker_percent",
       [](RealismOptions& r) -> double& { return r.appearance.cam1_gain_flicker_percent; }, "%",
       "measured", "cam1's, same measurement"},
      {S::kAppearance, "appearance.veiling_glare_percent",
       [](RealismOptions& r) -> double& { return r.appearance.veiling_glare_percent; }, "%",
       "not measured",
       "ISO 9358 veiling glare; issue 38 tried it, off in the preset (docs/realism.md)"},
      {S::kAppearance, "appearance.exposure_at_unit_gain_ms",
       [](RealismOptions& r) -> double& { return r.appearance.exposure_at_unit_gain_ms; }, "ms",
       "model", "exposure the renderer's radiance 1 needs for full scale (sets typical exposure)"},
      {S::kCalibration, "calibration.focal_px",
       [](RealismOptions& r) -> double& { return r.calibration.focal_px; }, "px", "0.1-3.6",
       "Kalibr formal sigma 0.08-0.11 (kalibr #502, #137); VINS-Mono/Fusion EuRoC "
       "re-calibrations differ by 2.5-3.6"},
      {S::kCalibration, "calibration.principal_point_px",
       [](RealismOptions& r) -> double& { return r.calibration.principal_point_px; }, "px",
       "0.02-6", "Kalibr sigma 0.02-0.7 (kalibr #137); EuRoC re-calibrations differ by 0.2-5.9"},
      {S::kCalibration, "calibration.k1",
       [](RealismOptions& r) -> double& { return r.calibration.k1; }, "", "0.001-0.012",
       "Kalibr sigma 0.0012-0.0042; re-calibrations differ by 0.006-0.012"},
      {S::kCalibration, "calibration.k2",
       [](RealismOptions& r) -> double& { return r.calibration.k2; }, "", "0.002-0.018",
       "Kalibr sigma 0.0017-0.018; re-calibrations differ by 0.006-0.013"},
      {S::kCalibration, "calibration.tangential",
       [](RealismOptions& r) -> double& { return r.calibration.tangential; }, "", "1e-4-4e-4",
       "Kalibr sigma of p1, p2 (kalibr #502, #137)"},
      {S::kCalibration, "calibration.per_camera_fraction",
       [](RealismOptions& r) -> double& { return r.calibration.per_camera_fraction; }, "x",
       "0.2-0.3",
       "VINS-Fusion's EuRoC re-calibration: cam0/cam1 differ by 0.7 px in f and "
       "1.3 px in cx against common shifts of 2.8 and 5.2"},
      {S::kCalibration, "calibration.stereo_rotation_deg",
       [](RealismOptions& r) -> double& { return r.calibration.stereo_rotation_deg; }, "deg",
       "0.014-0.12", "Kalibr stereo outputs of 3-12 cm rigs (0.25-2.1 mrad)"},
      {S::kCalibration, "calibration.stereo_translation_mm",
       [](RealismOptions& r) -> double& { return r.calibration.stereo_translation_mm; }, "mm",
       "0.03-0.6", "Kalibr stereo outputs; Basalt's EuRoC baseline differs by 0.16"},
      {S::kCalibration, "calibration.imu_rotation_deg",
       [](RealismOptions& r) -> double& { return r.calibration.imu_rotation_deg; }, "deg",
       "0.05-0.34", "Basalt's EuRoC camera-IMU rotation differs from the official by 0.34"},
      {S::kCalibration, "calibration.imu_translation_mm",
       [](RealismOptions& r) -> double& { return r.calibration.imu_translation_mm; }, "mm", "1-8",
       "Basalt's EuRoC camera-IMU translation differs from the official by 8"},
      {S::kTiming, "timing.camera_imu_offset_ms",
       [](RealismOptions& r) -> double& { return r.timing.camera_imu_offset_ms; }, "ms", "-2-2",
       "Kalibr repeatability on a hardware-triggered rig (kalibr #267); EuRoC treated as 0 by "
       "VINS-Fusion"},
      {S::kTiming, "timing.jitter_ms",
       [](RealismOptions& r) -> double& { return r.timing.jitter_ms; }, "ms", "0.01-0.1",
       "FPGA time stamping of the VI-Sensor (inference; no published figure)"},
      {S::kImu, "imu.gyro_scale_pct",
       [](RealismOptions& r) -> double& { return r.imu.gyro_scale_pct; }, "%", "0.1-0.5",
       "factory-calibrated ADIS parts (inference; ADIS16448 table not reachable)"},
      {S::kImu, "imu.accel_scale_pct",
       [](RealismOptions& r) -> double& { return r.imu.accel_scale_pct; }, "%", "0.1-0.5",
       "static |a| of the real V1_01 IMU is 0.9966 x 9.81 (imu_vibration.py)"},
      {S::kImu, "imu.gyro_misalignment_deg",
       [](RealismOptions& r) -> double& { return r.imu.gyro_misalignment_deg; }, "deg", "0-0.05",
       "ADIS16448 datasheet: axis-to-axis alignment < 0.05"},
      {S::kImu, "imu.accel_misalignment_deg",
       [](RealismOptions& r) -> double& { return r.imu.accel_misalignment_deg; }, "deg", "0-0.05",
       "ADIS16448 datasheet: axis-to-axis alignment < 0.05"},
      {S::kImu, "imu.gyro_g_sensitivity_dps_per_g",
       [](RealismOptions& r) -> double& { return r.imu.gyro_g_sensitivity_dps_per_g; }, "deg/s/g",
       "0-0.015", "ADIS16445 (sibling) linear-acceleration effect 0.015"},
      {S::kImu, "imu.gyro_bias_rad_s",
       [](RealismOptions& r) -> double& { return r.imu.gyro_bias_rad_s; }, "rad/s", "0.002-0.08",
       "EuRoC turn-on biases (-0.002, 0.024, 0.077) (Basalt EuRoC calibration; our V1_01 IMU)"},
      {S::kImu, "imu.accel_bias_m_s2",
       [](RealismOptions& r) -> double& { return r.imu.accel_bias_m_s2; }, "m/s^2", "0.002-0.15",
       "EuRoC turn-on biases (0.002, 0.15, 0.067) (Basalt EuRoC calibration)"},
      {S::kImu, "imu.gyro_quantum_rad_s",
       [](RealismOptions& r) -> double& { return r.imu.gyro_quantum_rad_s; }, "rad/s", "6.98e-4",
       "VI-Sensor driver: 0.04 deg/s per LSB (libvisensor imu_adis16448.cpp)"},
      {S::kImu, "imu.accel_quantum_m_s2",
       [](RealismOptions& r) -> double& { return r.imu.accel_quantum_m_s2; }, "m/s^2", "8.18e-3",
       "VI-Sensor driver: 1/1200 g per LSB"},
      {S::kMotion, "motion.position_cutoff_hz",
       [](RealismOptions& r) -> double& { return r.motion.position_cutoff_hz; }, "Hz", "4-7",
       "twice the motion knee of the five ground truths (gt_smoothness.py); above it, "
       "vibration"},
      {S::kMotion, "motion.rotation_cutoff_hz",
       [](RealismOptions& r) -> double& { return r.motion.rotation_cutoff_hz; }, "Hz", "4-7",
       "as position; the ground truths carry a 20 Hz glitch that must not be differentiated"},
      {S::kMotion, "motion.position_knot_s",
       [](RealismOptions& r) -> double& { return r.motion.position_knot_s; }, "s", "model",
       "spline knot spacing of the replay"},
      {S::kMotion, "motion.rotation_knot_s",
       [](RealismOptions& r) -> double& { return r.motion.rotation_knot_s; }, "s", "model",
       "spline knot spacing of the replay"},
      {S::kMotion, "motion.vibration_scale",
       [](RealismOptions& r) -> double& { return r.motion.vibration_scale; }, "x", "measured",
       "residual spectrum of the real V1_01 IMU in flight (imu_vibration.py)"},
      {S::kGroundTruth, "ground_truth.position_noise_mm",
       [](RealismOptions& r) -> double& { return r.ground_truth.position_noise_mm; }, "mm",
       "0.15-2",
       "Vicon static 0.15 / dynamic < 2 (Merriaux et al. 2017); Leica ~1; the MH files "
       "step by up to 8 (gt_smoothness.py)"},
      {S::kGroundTruth, "ground_truth.rotation_noise_deg",
       [](RealismOptions& r) -> double& { return r.ground_truth.rotation_noise_deg; }, "deg",
       "0.01-0.1", "motion-capture orientation (inference)"},
      {S::kGroundTruth, "ground_truth.time_offset_ms",
       [](RealismOptions& r) -> double& { return r.ground_truth.time_offset_ms; }, "ms", "measured",
       "ground truth vs the real V1_01 IMU by cross-correlation (imu_vibration.py)"},
  };
  return kTable;
}

}  // namespace

void SetRealismParameter(RealismOptions* options, const std::string& name, double value) {
  for (const ParameterRow& row : ParameterTable()) {
    if (name == row.name) {
      row.field(*options) = value;
      options->Check();
      return;
    }
  }
  std::string names;
  for (const ParameterRow& row : ParameterTable()) names += std::string(" ") + row.name;
  throw OptionError("unknown realism parameter '" + name + "'; known:" + names);
}

void SetRealismParameter(RealismOptions* options, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw OptionError("--realism-param needs NAME=VALUE, got '" + assignment + "'");
  }
  const std::string value_text = assignment.substr(eq + 1);
  char* end = nullptr;
  const double value = std::strtod(value_text.c_str(), &end);
  if (value_text.empty() || end == nullptr || *end != '\0' || !std::isfinite(value)) {
    throw OptionError("--realism-param " + assignment + ": '" + value_text + "' is not a number");
  }
  SetRealismParameter(options, assignment.substr(0, eq), value);
}

std::vector<RealismEntry> RealismReport(const RealismOptions& options) {
  RealismOptions copy = options;
  std::vector<RealismEntry> out;
  for (const ParameterRow& row : ParameterTable()) {
    const double value = copy.On(row.source) ? row.field(copy) : 0.0;
    out.push_back({row.source, row.name, value, row.unit, row.range, row.reference});
  }
  return out;
}

std::string FormatRealismReport(const RealismOptions& options) {
  std::string text = fmt::format("realism preset: {}\n", RealismPresetName(options.preset));
  for (RealismSource s : kRealismSources) {
    text += fmt::format("  {:<13} {}\n", RealismSourceName(s), options.On(s) ? "on" : "off");
  }
  text += fmt::format("device seed (calibration, IMU axes): {}\n", options.device_seed);
  text += fmt::format("{:<36} {:>10} {:<9} {:<11} {}\n", "parameter", "value", "unit", "documented",
                      "source");
  for (const RealismEntry& e : RealismReport(options)) {
    text += fmt::format("{:<36} {:>10.4g} {:<9} {:<11} {}\n", e.name, e.value, e.unit, e.range,
                        e.reference);
  }
  return text;
}

RealismOptions ResolveRealism(const RealismRequest& request) {
  const RealismPreset preset =
      request.preset.empty()
          ? (request.replay && !request.rgbd ? RealismPreset::kEuroc : RealismPreset::kIdeal)
          : ParseRealismPreset(request.preset);
  if (preset == RealismPreset::kEuroc && request.rgbd) {
    throw OptionError(
        "--realism euroc models the EuRoC VI-Sensor (stereo + IMU); use --realism ideal with "
        "--rgbd");
  }
  RealismOptions r = MakeRealism(preset);
  r.device_seed = request.device_seed;
  for (const std::string& name : request.off) {
    if (preset == RealismPreset::kIdeal) {
      throw OptionError("--realism-off needs --realism euroc (ideal has every source off)");
    }
    r.enabled[static_cast<std::size_t>(ParseRealismSource(name))] = false;
  }
  for (const std::string& p : request.params) SetRealismParameter(&r, p);
  return r;
}

}  // namespace pkslam::sim
