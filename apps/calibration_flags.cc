#include "apps/calibration_flags.h"

#include <cctype>

namespace pkslam::apps {
namespace {

// "CONDITION, SENSORS: TEXT" with the empty parts left out; capitalised when nothing precedes
// the text. TEXT ends in a parenthesis, which takes the pointer to the docs.
std::string Help(const std::string& condition, const std::string& sensors, std::string text) {
  // "... (held by default)" -> "... (held by default; docs/calibration.md)"
  text.insert(text.size() - 1, "; docs/calibration.md");
  std::string prefix = condition;
  if (!sensors.empty()) prefix += (prefix.empty() ? "" : ", ") + sensors;
  if (prefix.empty()) {
    text[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(text[0])));
    return text;
  }
  return prefix + ": " + text;
}

}  // namespace

void AddCalibrationFreedomFlags(CLI::App* cmd, OnlineCalibrationOptions* options,
                                const std::string& condition) {
  cmd->add_flag("--calibrate-lever-arm", options->imu_translation,
                Help(condition, "",
                     "estimate the camera-IMU translation too (held at the file's value by "
                     "default)"));
  cmd->add_flag("--calibrate-mono-intrinsics", options->monocular_intrinsics,
                Help(condition, "monocular-inertial",
                     "estimate the camera's intrinsics too (held at the file's values by "
                     "default)"));
  cmd->add_flag("--calibrate-hold-gyro-scale{false}", options->gyro_scale,
                Help(condition, "inertial",
                     "hold the gyroscope's scale factors at the file's values (estimated by "
                     "default)"));
  cmd->add_flag("--calibrate-hold-accel-axes{false}", options->accel_axes,
                Help(condition, "inertial",
                     "hold the accelerometer's misalignment at the file's values (estimated by "
                     "default on a stereo-inertial rig)"));
  cmd->add_flag("--calibrate-mono-accel-axes", options->monocular_accel_axes,
                Help(condition, "monocular-inertial",
                     "estimate the accelerometer's misalignment too (held at the file's values "
                     "by default)"));
  cmd->add_flag("--calibrate-accel-scale", options->accel_scale,
                Help(condition, "inertial",
                     "estimate the accelerometer's per-axis scale factors too (held by "
                     "default)"));
}

}  // namespace pkslam::apps
