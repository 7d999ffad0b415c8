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
    std::copy_n(grey.ptr<std::uint8_t>(y), grey.cols,
                base.grey.data() + static_cast<std::ptrdiff_t>(y) * grey.cols);
  }
  if (has_colour_) {
    base.rgb.resize(static_cast<std::size_t>(grey.total()) * 3);
    for (int y = 0; y < colour.rows; ++y) {
      std::copy_n(colour.ptr<std::uint8_t>(y), colour.cols * 3,
                  base.rgb.data() + static_cast<std::ptrdiff_t>(y) * colour.cols * 3);
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

}  // namespace pkslam::sim
