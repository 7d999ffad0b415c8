// 256-bit binary (ORB / rBRIEF) descriptors as plain values, and Hamming distance.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>

namespace pkslam {

// 32 bytes, bit i of the rBRIEF test sequence at byte i/8, bit i%8 (OpenCV's layout, so a
// row of a cv::ORB descriptor Mat copies in with memcpy).
struct Descriptor {
  alignas(8) std::array<std::uint8_t, 32> bytes{};

  friend bool operator==(const Descriptor&, const Descriptor&) = default;
};

inline int HammingDistance(const Descriptor& a, const Descriptor& b) {
  int d = 0;
  for (int i = 0; i < 4; ++i) {
    std::uint64_t x;
    std::uint64_t y;
    std::memcpy(&x, a.bytes.data() + 8 * i, 8);
    std::memcpy(&y, b.bytes.data() + 8 * i, 8);
    d += std::popcount(x ^ y);
  }
  return d;
}

}  // namespace pkslam
