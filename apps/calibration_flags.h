// The flags that choose what online calibration estimates beyond its defaults
// (docs/calibration.md, "What is estimated"), shared by `pkslam run` and `pkslam calibrate` so
// the two commands name and explain them alike.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "mapping/calibration_refinement.h"

namespace pkslam::apps {

// Adds --calibrate-lever-arm, --calibrate-mono-intrinsics, --calibrate-hold-gyro-scale,
// --calibrate-hold-accel-axes, --calibrate-mono-accel-axes and --calibrate-accel-scale, writing
// into `options` (which must outlive the parse). `condition`: what the flags wait for, as their
// help says it ("--calibrate online" for run; empty for calibrate, which always calibrates).
void AddCalibrationFreedomFlags(CLI::App* cmd, OnlineCalibrationOptions* options,
                                const std::string& condition);

}  // namespace pkslam::apps
