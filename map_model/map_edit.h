// The kinds of change the map model goes through (map_editor.h), and the statistics of the
// exclusive lock held for each.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace pkslam {

enum class MapEdit : std::uint8_t {
  kInitialise,              // tracking: a new map (stereo/depth or two views) and its first BA
  kInsertKeyFrame,          // tracking: a keyframe and its stereo/depth points enter the map
  kReset,                   // tracking: the current map cleared, or a new one after a loss
  kProcessKeyFrame,         // local mapping: a keyframe's observations and connections
  kCullPoints,              // local mapping: recent points that did not hold up
  kCreatePoints,            // local mapping: triangulation with the neighbours
  kFuse,                    // local mapping: duplicate points merged
  kCullKeyFrames,           // local mapping: redundant keyframes retired
  kApplyBundle,             // local mapping: a local BA result written back
  kApplyInertialBundle,     // local mapping: an inertial BA result (poses, velocities, biases)
  kInertialInitialisation,  // local mapping: IMU initialisation / scale and gravity refinement
  kCalibration,             // local mapping / system: a calibration estimate applied to the map
  kLoopCorrection,          // loop closing: a loop's correction and the essential graph
  kMergeMaps,               // loop closing: two maps merged
  kGlobalBundle,            // loop closing: a global BA result merged in
  kLoadMap,                 // system: a map file restored into the Atlas (--load-map)
  kFixture,                 // tests and benchmarks that build maps by hand
};
inline constexpr int kNumMapEdits = static_cast<int>(MapEdit::kFixture) + 1;

std::string_view MapEditName(MapEdit edit);

// Exclusive holds of one kind: how many, and how long in total and at most (wall seconds).
struct MapEditStats {
  std::int64_t holds = 0;
  double total_s = 0;
  double max_s = 0;
};
using MapEditTable = std::array<MapEditStats, kNumMapEdits>;

}  // namespace pkslam
