// Mip-mapped textures for the renderer: 8-bit grey (always) and colour (RGB-D output),
// pyramid precomputed once, sampled trilinearly at a level of detail chosen from the pixel's
// footprint on the surface, so distant surfaces are filtered instead of aliased.
//
// Texel centres: texel i of a level of width W covers [i, i+1)/W in texture coordinates; a
// sample at coordinate s reads position s*W - 0.5 (so a box-filtered level stays aligned).
#pragma once

#include <Eigen/Core>
#include <bit>
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace pkslam::sim {

class MipTexture {
 public:
  MipTexture() = default;
  // grey: CV_8UC1 base level; colour: empty or CV_8UC3 (RGB order) of the same size.
  // repeat: texture coordinates wrap (dimensions must be powers of two); otherwise they clamp.
  MipTexture(const cv::Mat& grey, const cv::Mat& colour, bool repeat);

  int width() const { return levels_.empty() ? 0 : levels_[0].width; }
  int height() const { return levels_.empty() ? 0 : levels_[0].height; }
  int num_levels() const { return static_cast<int>(levels_.size()); }
  bool has_colour() const { return has_colour_; }
  bool repeat() const { return repeat_; }
  // Level-0 image (for the reference point cloud and debugging).
  cv::Mat BaseGrey() const;

  // Grey value in [0, 1] at texture coordinates (s, t) (one unit = the whole texture), with
  // lod = log2(texels covered by the pixel footprint at level 0).
  float SampleGrey(float s, float t, float lod) const;
  Eigen::Vector3f SampleColour(float s, float t, float lod) const;

 private:
  struct Level {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> grey;
    std::vector<std::uint8_t> rgb;  // interleaved, empty without colour
  };

  template <int Channels>
  void Bilinear(const Level& level, float s, float t, float* out) const;
  template <int Channels>
  void Trilinear(float s, float t, float lod, float* out) const;

  std::vector<Level> levels_;
  bool repeat_ = true;
  bool has_colour_ = false;
};

// Fast log2 approximation (|error| < 0.01) for level-of-detail selection; x must be a
// positive normal float. Deterministic (integer bit manipulation and two multiplies).
inline float FastLog2(float x) {
  const auto bits = std::bit_cast<std::uint32_t>(x);
  const int exponent = static_cast<int>((bits >> 23) & 0xFFu) - 127;
  const float m = static_cast<float>(bits & 0x7FFFFFu) * (1.0f / 8388608.0f);  // [0, 1)
  // log2(1 + m) by a quadratic through m = 0, 1 and (nearly) 0.5.
  return static_cast<float>(exponent) + m * (1.3465f - 0.3465f * m);
}

}  // namespace pkslam::sim
