// Typed ids of the map's objects. They live in the base layer so that estimators (which take
// and return values, never map objects) and sensor-level code can name keyframes and points;
// the objects themselves and their shared-pointer aliases are in map_model/map_ids.h.
#pragma once

#include <cstdint>

namespace pkslam {

using FrameId = std::int64_t;
using KeyFrameId = std::int64_t;
using MapPointId = std::int64_t;
using MapId = std::int64_t;
inline constexpr std::int64_t kInvalidId = -1;

}  // namespace pkslam
