// Typed ids and shared-pointer aliases of the map model (see docs/architecture.md).
#pragma once

#include <cstdint>
#include <memory>

namespace pkslam {

using FrameId = std::int64_t;
using KeyFrameId = std::int64_t;
using MapPointId = std::int64_t;
using MapId = std::int64_t;
inline constexpr std::int64_t kInvalidId = -1;

class Frame;
class KeyFrame;
class MapPoint;
class Map;
class Atlas;

using KeyFramePtr = std::shared_ptr<KeyFrame>;
using MapPointPtr = std::shared_ptr<MapPoint>;

}  // namespace pkslam
