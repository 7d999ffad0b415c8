// The realism of a simulated sequence: the error sources that separate a clean rendering from
// a real EuRoC recording. `ideal` renders today's clean sequences (exact calibration, exact
// timing, a perfect IMU axis model, smoothed motion, exact ground truth); `euroc` switches every
// source on with sizes from documented sources (docs/realism.md lists each with its reference;
// RealismReport() prints them). Each source can be switched off alone for ablations, and each
// size can be overridden by name (SetRealismParameter).
//
// The device errors (calibration, IMU axes, time offset) are drawn once from `device_seed`, not
// from the sequence seed: EuRoC shares one calibration between its sequences, so the replays of
// different trajectories see the same miscalibrated rig, as the real ones did.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace pkslam::sim {

enum class RealismPreset { kIdeal, kEuroc };
RealismPreset ParseRealismPreset(const std::string& name);  // ideal|euroc; OptionError
std::string RealismPresetName(RealismPreset preset);

enum class RealismSource { kAppearance, kCalibration, kTiming, kImu, kMotion, kGroundTruth };
inline constexpr std::array<RealismSource, 6> kRealismSources = {
    RealismSource::kAppearance, RealismSource::kCalibration, RealismSource::kTiming,
    RealismSource::kImu,        RealismSource::kMotion,      RealismSource::kGroundTruth};
// appearance|calibration|timing|imu|motion|ground-truth; OptionError for other names.
RealismSource ParseRealismSource(const std::string& name);
std::string RealismSourceName(RealismSource source);

// What SLAM reads differs from the rendering truth by these (1-sigma, per component). The
// intrinsic errors are common to both cameras plus a smaller per-camera part: a calibration
// moves the two cameras of a rig alike (EuRoC's re-calibrations shift cx by -4.6 and -5.9 px),
// and stereo depth only sees the difference.
struct CalibrationErrorOptions {
  double focal_px = 0.0;               // fx, fy (pixels)
  double principal_point_px = 0.0;     // cx, cy (pixels)
  double k1 = 0.0;                     // radial k1
  double k2 = 0.0;                     // radial k2
  double tangential = 0.0;             // p1, p2
  double per_camera_fraction = 0.0;    // sigma of each camera's own part / the common sigma
  double stereo_rotation_deg = 0.0;    // cam1 relative to cam0, per axis
  double stereo_translation_mm = 0.0;  // cam1 relative to cam0, per axis
  double imu_rotation_deg = 0.0;       // the camera rig relative to the IMU, per axis
  double imu_translation_mm = 0.0;     // the camera rig relative to the IMU, per axis

  void Check() const;
};

struct TimingErrorOptions {
  // t_imu = t_image + offset: the image stamped t shows the scene at IMU time t + offset
  // (Kalibr's timeshift_cam_imu convention). A fixed value, as a hardware-synchronised rig has.
  double camera_imu_offset_ms = 0.0;
  double jitter_ms = 0.0;  // per-frame exposure-time jitter (1-sigma), stamps stay on the grid

  void Check() const;
};

struct ImuErrorOptions {
  double gyro_scale_pct = 0.0;                // per-axis scale-factor error (1-sigma, %)
  double accel_scale_pct = 0.0;               // per-axis scale-factor error (1-sigma, %)
  double gyro_misalignment_deg = 0.0;         // axis non-orthogonality, per off-diagonal (1-sigma)
  double accel_misalignment_deg = 0.0;        // axis non-orthogonality, per off-diagonal (1-sigma)
  double gyro_g_sensitivity_dps_per_g = 0.0;  // per matrix entry (1-sigma, deg/s per g)
  double gyro_bias_rad_s = 0.0;     // initial gyro bias per axis (1-sigma), drawn per sequence
  double accel_bias_m_s2 = 0.0;     // initial accelerometer bias per axis (1-sigma), per sequence
  double gyro_quantum_rad_s = 0.0;  // output resolution (0: none)
  double accel_quantum_m_s2 = 0.0;  // output resolution (0: none)

  void Check() const;
};

struct MotionRealismOptions {
  // Replay fit: knots and cutoffs of the spline through the ground truth. Below the cutoff
  // the replay keeps the recorded motion; above it, the vibration spectrum takes over.
  double position_knot_s = 0.05;
  double rotation_knot_s = 0.05;
  double position_cutoff_hz = 10.0;
  double rotation_cutoff_hz = 10.0;
  bool vibration = false;        // rotor vibration as real motion (sim/vibration.h)
  double vibration_scale = 1.0;  // amplitude factor on the measured spectrum

  void Check() const;
};

struct GroundTruthErrorOptions {
  double position_noise_mm = 0.0;   // white noise on the written positions (1-sigma, per axis)
  double rotation_noise_deg = 0.0;  // white noise on the written orientations (1-sigma, per axis)
  double time_offset_ms = 0.0;      // the row stamped t holds the true state at t + offset

  void Check() const;
};

struct AppearanceOptions {
  // Scene when the user gives none: the EuRoC-like rooms (sparse texture, saturating
  // windows and lamps) for Vicon-room and machine-hall trajectories.
  std::string vicon_scene = "vicon_room";
  std::string machine_hall_scene = "machine_hall";
  double read_noise_dn = 1.0;     // Gaussian read noise (8-bit levels)
  double shot_noise_gain = 0.04;  // shot-noise variance per level
  double blur_sigma_px = 0.5;     // optical blur
  double vignetting = 0.35;
  double target_brightness = 0.42;  // auto-exposure target (mean 8-bit level / 255, clipped)
  double cam1_relative_gain = 1.0;  // cam1's response relative to cam0's
  double exposure_adapt = 0.3;      // auto-exposure correction per frame (its lag)
  double max_exposure_ms = 0.0;     // > 0: motion blur over the auto-exposure time, capped here
  double exposure_at_unit_gain_ms = 1.0;   // exposure time the radiance scale 1 needs
  double gain_flicker_percent = 0.0;       // cam0's frame-to-frame gain change (std, %)
  double cam1_gain_flicker_percent = 0.0;  // cam1's
  double veiling_glare_percent = 0.0;      // share of the light scattered as veiling glare

  void Check() const;
};

struct RealismOptions {
  RealismPreset preset = RealismPreset::kIdeal;
  std::array<bool, kRealismSources.size()> enabled{};  // by RealismSource
  CalibrationErrorOptions calibration;
  TimingErrorOptions timing;
  ImuErrorOptions imu;
  MotionRealismOptions motion;
  GroundTruthErrorOptions ground_truth;
  AppearanceOptions appearance;
  std::uint64_t device_seed = 1;  // calibration, IMU axes, time offset (see file comment)

  bool On(RealismSource s) const { return enabled[static_cast<std::size_t>(s)]; }
  void Check() const;
};

// The options of a preset with every source on (kIdeal: every source off, ideal sizes).
RealismOptions MakeRealism(RealismPreset preset);

// Sets a size by its report name ("calibration.focal_px", "timing.camera_imu_offset_ms",
// "motion.vibration_scale", ...); OptionError for unknown names or bad values.
void SetRealismParameter(RealismOptions* options, const std::string& name, double value);
// "name=value" form of the above (the CLI's --realism-param).
void SetRealismParameter(RealismOptions* options, const std::string& assignment);

// What a render asks for (pkslam simulate's --realism, --realism-off, --realism-param,
// --device-seed; the Python module's simulate()).
struct RealismRequest {
  std::string preset;   // "ideal" | "euroc"; empty: euroc for a stereo replay, ideal otherwise
  bool replay = false;  // a recorded trajectory is replayed
  bool rgbd = false;    // TUM RGB-D output (no euroc preset: it models the VI-Sensor)
  std::vector<std::string> off;     // sources switched off (euroc only)
  std::vector<std::string> params;  // "name=value" size overrides
  std::uint64_t device_seed = 1;
};

// The realism options a request resolves to; OptionError naming the flag otherwise.
RealismOptions ResolveRealism(const RealismRequest& request);

// One line of the realism report: an error source's size and where the size comes from.
struct RealismEntry {
  RealismSource source;
  std::string name;  // parameter name (SetRealismParameter)
  double value;      // the size in use
  std::string unit;
  std::string range;  // the documented range
  std::string reference;
};
std::vector<RealismEntry> RealismReport(const RealismOptions& options);
// The report as aligned text (pkslam simulate --realism-report).
std::string FormatRealismReport(const RealismOptions& options);

}  // namespace pkslam::sim
