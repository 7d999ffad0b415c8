#include "sim/texture.h"

#include <algorithm>

#include "core/util/error.h"

namespace pkslam::sim {
namespace {

bool IsPowerOfTwo(int v) { return v > 0 && (v & (v - 1)) == 0; }

}  // namespace

MipTexture::MipTexture(const cv::Mat& grey, const cv::Mat& colour, bool repeat)
    : repeat_(repeat), has_colour_(!colour.empty()) {
  PKSLAM_CHECK(grey.type() == CV_8UC1 && !grey.empty(), "texture must be 8-bit grey");
  PKSLAM_CHECK(!has_colour_ || (colour.type() == CV_8UC3 && colour.size() == grey.size()),
               "colour texture must be 8-bit RGB of the grey size");
  PKSLAM_CHECK(!repeat || (IsPowerOfTwo(grey.cols) && IsPowerOfTwo(grey.rows)),
               "repeating texture needs power-of-two size, got {}x{}", grey.cols, grey.rows);
  Level base;
  base.width = grey.cols;
  base.height = grey.rows;
  base.grey.resize(static_cast<std::size_t>(grey.total()));
  for (int y = 0; y < grey.rows; ++y) {
    std::copy_n(grey.ptr<std::uint8_t>(y), grey.cols, base.grey.data() + y * grey.cols);
  }
  if (has_colour_) {
    base.rgb.resize(static_cast<std::size_t>(grey.total()) * 3);
    for (int y = 0; y < colour.rows; ++y) {
      std::copy_n(colour.ptr<std::uint8_t>(y), colour.cols * 3,
                  base.rgb.data() + y * colour.cols * 3);
    }
  }
  levels_.push_back(std::move(base));
  // 2x2 box pyramid while both sides halve exactly (keeps texel centres aligned).
  while (levels_.back().width % 2 == 0 && levels_.back().height % 2 == 0 &&
         levels_.back().width > 1 && levels_.back().height > 1) {
    const Level& src = levels_.back();
    Level dst;
    dst.width = src.width / 2;
    dst.height = src.height / 2;
    dst.grey.resize(static_cast<std::size_t>(dst.width) * dst.height);
    if (has_colour_) dst.rgb.resize(dst.grey.size() * 3);
    for (int y = 0; y < dst.height; ++y) {
      for (int x = 0; x < dst.width; ++x) {
        const int a = (2 * y) * src.width + 2 * x;
        const int b = a + src.width;
        const int sum = src.grey[a] + src.grey[a + 1] + src.grey[b] + src.grey[b + 1];
        dst.grey[y * dst.width + x] = static_cast<std::uint8_t>((sum + 2) / 4);
        if (has_colour_) {
          for (int c = 0; c < 3; ++c) {
            const int s = src.rgb[3 * a + c] + src.rgb[3 * (a + 1) + c] + src.rgb[3 * b + c] +
                          src.rgb[3 * (b + 1) + c];
            dst.rgb[3 * (y * dst.width + x) + c] = static_cast<std::uint8_t>((s + 2) / 4);
          }
        }
      }
    }
    levels_.push_back(std::move(dst));
  }
}

cv::Mat MipTexture::BaseGrey() const {
  const Level& l = levels_.at(0);
  cv::Mat m(l.height, l.width, CV_8UC1);
  std::copy(l.grey.begin(), l.grey.end(), m.ptr<std::uint8_t>(0));
  return m;
}

template <int Channels>
void MipTexture::Bilinear(const Level& level, float s, float t, float* out) const {
  const std::uint8_t* data = Channels == 1 ? level.grey.data() : level.rgb.data();
  float x = s * static_cast<float>(level.width) - 0.5f;
  float y = t * static_cast<float>(level.height) - 0.5f;
  const float fx0 = std::floor(x);
  const float fy0 = std::floor(y);
  const float ax = x - fx0;
  const float ay = y - fy0;
  int x0 = static_cast<int>(fx0);
  int y0 = static_cast<int>(fy0);
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
void MipTexture::Trilinear(float s, float t, float lod, float* out) const {
  if (repeat_) {
    // Wrap first so large coordinates keep their fractional precision.
    s -= std::floor(s);
    t -= std::floor(t);
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

float MipTexture::SampleGrey(float s, float t, float lod) const {
  float v = 0.0f;
  Trilinear<1>(s, t, lod, &v);
  return v;
}

Eigen::Vector3f MipTexture::SampleColour(float s, float t, float lod) const {
  Eigen::Vector3f v;
  if (!has_colour_) {
    v.setConstant(SampleGrey(s, t, lod));
    return v;
  }
  Trilinear<3>(s, t, lod, v.data());
  return v;
}

}  // namespace pkslam::sim
