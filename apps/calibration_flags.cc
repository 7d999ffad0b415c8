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

// One flag: its name (CLI11's "{false}" makes a "hold" flag clear the option), the option it
// sets, the sensors it concerns (empty: every calibrating one) and its help.
struct FreedomFlag {
  const char* name;
  bool OnlineCalibrationOptions::*option;
  const char* sensors;
  const char* text;
};

constexpr FreedomFlag kFreedomFlags[] = {
    {"--calibrate-lever-arm", &OnlineCalibrationOptions::imu_translation, "",
     "estimate the camera-IMU translation too (held at the file's value by default)"},
    {"--calibrate-mono-intrinsics", &OnlineCalibrationOptions::monocular_intrinsics,
     "monocular-inertial",
     "estimate the camera's intrinsics too (held at the file's values by default)"},
    {"--calibrate-hold-gyro-scale{false}", &OnlineCalibrationOptions::gyro_scale, "inertial",
     "hold the gyroscope's scale factors at the file's values (estimated by default)"},
    {"--calibrate-hold-accel-axes{false}", &OnlineCalibrationOptions::accel_axes, "inertial",
     "hold the accelerometer's misalignment at the file's values (estimated by default on a "
     "stereo-inertial rig)"},
    {"--calibrate-mono-accel-axes", &OnlineCalibrationOptions::monocular_accel_axes,
     "monocular-inertial",
     "estimate the accelerometer's misalignment too (held at the file's values by default)"},
    {"--calibrate-accel-scale", &OnlineCalibrationOptions::accel_scale, "inertial",
     "estimate the accelerometer's per-axis scale factors too (held by default)"},
};

}  // namespace

void AddCalibrationFreedomFlags(CLI::App* cmd, OnlineCalibrationOptions* options,
                                const std::string& condition) {
  for (const FreedomFlag& flag : kFreedomFlags) {
    cmd->add_flag(flag.name, options->*flag.option, Help(condition, flag.sensors, flag.text));
  }
}

}  // namespace pkslam::apps
