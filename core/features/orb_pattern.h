// The standard ORB (rBRIEF) test pattern: the published numeric definition of the descriptor.
#pragma once

#include <cstddef>
#include <span>

namespace pkslam {

// Number of binary tests (bits) in an ORB descriptor.
inline constexpr std::size_t kOrbDescriptorBits = 256;

// The 256 point-pair tests for a 31x31 patch, flattened as x1 y1 x2 y2 per test (pixels,
// relative to the keypoint, x right, y down, before rotation by the keypoint angle).
std::span<const int, 4 * kOrbDescriptorBits> OrbPattern31();

}  // namespace pkslam
