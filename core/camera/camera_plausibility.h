// Is a calibration a camera at all? Absurd numbers (a typo in cx, k1: 50, a sign lost) used to
// run with rectified focal lengths of tens of thousands of pixels and track nothing, exit 0.
// These gates are far wider than any real lens (EuRoC's cameras sit well inside every one), so a
// camera that fails them is a mistake in the file, not an unusual lens.
#pragma once

#include <optional>
#include <string>

#include "core/camera/camera_model.h"

namespace pkslam {

struct ImplausibleParameter {
  std::string parameter;  // "fx", "fy", "cx", "cy" or "distortion"
  std::string what;       // the value and the bound it breaks, for the user
};

// Focal lengths within [0.05, 6] x the image width (fields of view of about 170 to 9 degrees)
// and fy/fx within [0.5, 2]; the principal point inside the image; radial-tangential
// distortion that maps the image corners one to one (undistorting and distorting again returns
// each corner within 0.5 px) and changes their distance from the centre by a factor within
// [1/4, 4]. Kannala-Brandt models: focal and principal point only.
std::optional<ImplausibleParameter> FindImplausibleParameter(const CameraModel& camera);

}  // namespace pkslam
