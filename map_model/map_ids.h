// The map model's classes and their shared-pointer aliases (see docs/architecture.md); the
// typed ids themselves are in core/util/ids.h.
#pragma once

#include <memory>

#include "core/util/ids.h"

namespace pkslam {

class Frame;
class KeyFrame;
class MapPoint;
class Map;
class Atlas;

using KeyFramePtr = std::shared_ptr<KeyFrame>;
using MapPointPtr = std::shared_ptr<MapPoint>;

}  // namespace pkslam
