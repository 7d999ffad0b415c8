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

// floor() for floats well inside the int range, without a libm call (the baseline x86-64
// target has no SSE4.1 round instruction).
inline int FloorToInt(float x) {
  const int i = static_cast<int>(x);
  return i - (x < static_cast<float>(i) ? 1 : 0);
}

// Fast log2 approximation (|error| < 0.01) for level-of-detail selection; x must be a
// positive normal float. Deterministic (integer bit manipulation and two multiplies).
inline float FastLog2(float x) {
  const auto bits = std::bit_cast<std::uint32_t>(x);
  const int exponent = static_cast<int>((bits >> 23) & 0xFFu) - 127;
  const float m = static_cast<float>(bits & 0x7FFFFFu) * (1.0f / 8388608.0f);  // [0, 1)
  // log2(1 + m) by a quadratic through m = 0, 1 and (nearly) 0.5.
  return static_cast<float>(exponent) + m * (1.3465f - 0.3465f * m);
}

// Sampling is inline: it runs for every rendered pixel.
template <int Channels>
inline void MipTexture::Bilinear(const Level& level, float s, float t, float* out) const {
  const std::uint8_t* data = Channels == 1 ? level.grey.data() : level.rgb.data();
  float x = s * static_cast<float>(level.width) - 0.5f;
  float y = t * static_cast<float>(level.height) - 0.5f;
  int x0 = FloorToInt(x);
  int y0 = FloorToInt(y);
  const float ax = x - static_cast<float>(x0);
  const float ay = y - static_cast<float>(y0);
  int x1 = x0 + 1;
  int y1 = y0 + 1;
  if (repeat_) {
    x0 &= level.width - 1;
    x1 &= level.width - 1;
    y0 &= level.height - 1;
    y1 &= level.height - 1;
  } else {
    x0 = std::clamp(x0, 0, level.width - 1);
    x1 = std::clamp(x1, 0, level.width - 1);
    y0 = std::clamp(y0, 0, level.height - 1);
    y1 = std::clamp(y1, 0, level.height - 1);
  }
  const std::uint8_t* r0 = data + static_cast<std::ptrdiff_t>(y0) * level.width * Channels;
  const std::uint8_t* r1 = data + static_cast<std::ptrdiff_t>(y1) * level.width * Channels;
  for (int c = 0; c < Channels; ++c) {
    const float top = r0[x0 * Channels + c] + ax * (r0[x1 * Channels + c] - r0[x0 * Channels + c]);
    const float bot = r1[x0 * Channels + c] + ax * (r1[x1 * Channels + c] - r1[x0 * Channels + c]);
    out[c] = (top + ay * (bot - top)) * (1.0f / 255.0f);
  }
}

template <int Channels>
inline void MipTexture::Trilinear(float s, float t, float lod, float* out) const {
  if (repeat_) {
    // Wrap first so large coordinates keep their fractional precision.
    s -= static_cast<float>(FloorToInt(s));
    t -= static_cast<float>(FloorToInt(t));
  }
  const float max_level = static_cast<float>(levels_.size() - 1);
  lod = std::clamp(lod, 0.0f, max_level);
  const int l0 = static_cast<int>(lod);
  const float f = lod - static_cast<float>(l0);
  Bilinear<Channels>(levels_[l0], s, t, out);
  if (f > 1e-3f && l0 + 1 < static_cast<int>(levels_.size())) {
    float upper[Channels];
    Bilinear<Channels>(levels_[l0 + 1], s, t, upper);
    for (int c = 0; c < Channels; ++c) out[c] += f * (upper[c] - out[c]);
  }
}

inline float MipTexture::SampleGrey(float s, float t, float lod) const {
  float v = 0.0f;
  Trilinear<1>(s, t, lod, &v);
  return v;
}

inline Eigen::Vector3f MipTexture::SampleColour(float s, float t, float lod) const {
  Eigen::Vector3f v;
  if (!has_colour_) {
    v.setConstant(SampleGrey(s, t, lod));
    return v;
  }
  Trilinear<3>(s, t, lod, v.data());
  return v;
}

}  // namespace pkslam::sim
