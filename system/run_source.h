// `pkslam run --video FILE | --camera N | --images DIR --timestamps FILE`: monocular SLAM over
// a FrameSource (io/frame_source.h) with the outputs, progress, Ctrl-C handling and map files of
// a dataset run (system/run_dataset.h). Needs --settings (the camera's calibration).
#pragma once

#include "io/frame_source.h"
#include "system/run_dataset.h"

namespace pkslam {

// options.dataset is only a label here (default: the source's name); options.settings is required
// and the sensor must be monocular (a video carries no IMU stream).
RunSummary RunFrameSource(const RunOptions& options, FrameSource& source,
                          const RunControl& control = {});

}  // namespace pkslam
