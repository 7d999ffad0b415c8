#include "core/features/orb_descriptor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <opencv2/imgproc.hpp>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/features/orb_pattern.h"

namespace pkslam {

std::vector<int> CircularPatchHalfWidths(int half_patch) {
  std::vector<int> u_max(half_patch + 2, 0);
  const double diag = half_patch * std::numbers::sqrt2 / 2.0;
  const int v_max = static_cast<int>(std::floor(diag + 1.0));
  const int v_min = static_cast<int>(std::ceil(diag));
  // Rows up to the 45 degree line from the circle equation...
  for (int v = 0; v <= v_max && v <= half_patch; ++v) {
    u_max[v] = static_cast<int>(std::lround(std::sqrt(double(half_patch * half_patch - v * v))));
  }
  // ...and the rows beyond it mirrored from the columns, so the disc is symmetric in x and y.
  int v0 = 0;
  for (int v = half_patch; v >= v_min; --v) {
    while (u_max[v0] == u_max[v0 + 1]) ++v0;
    u_max[v] = v0;
    ++v0;
  }
  u_max.resize(half_patch + 1);
  return u_max;
}

float IntensityCentroidAngle(const cv::Mat& image, cv::Point center, std::span<const int> u_max) {
  const int half = static_cast<int>(u_max.size()) - 1;
  const std::ptrdiff_t step = static_cast<std::ptrdiff_t>(image.step1());
  const std::uint8_t* c = image.ptr<std::uint8_t>(center.y) + center.x;
  int m_10 = 0;
  int m_01 = 0;
  for (int u = -half; u <= half; ++u) m_10 += u * c[u];
  // Rows v and -v together: their sum feeds m_10, their difference m_01.
  for (int v = 1; v <= half; ++v) {
    const std::uint8_t* below = c + v * step;
    const std::uint8_t* above = c - v * step;
    const int d = u_max[v];
    int diff_sum = 0;
    for (int u = -d; u <= d; ++u) {
      diff_sum += below[u] - above[u];
      m_10 += u * (below[u] + above[u]);
    }
    m_01 += v * diff_sum;
  }
  float angle =
      static_cast<float>(std::atan2(double(m_01), double(m_10)) * 180.0 / std::numbers::pi);
  if (angle < 0.0f) angle += 360.0f;
  if (angle >= 360.0f) angle -= 360.0f;
  return angle;
}

namespace {

// ORB's smoothing is OpenCV's bit-exact 8-bit Gaussian (7 taps, sigma 2): fixed-point taps
// {18, 34, 48, 56, 48, 34, 18} / 256 per axis, then (sum + 2^15) >> 16. All taps are even, so
// halving them keeps the row sums in int16 and the result is (sum' + 2^13) >> 14. The loops
// are written for the auto-vectoriser and cloned for AVX2.
constexpr int kTap0 = 9, kTap1 = 17, kTap2 = 24, kTap3 = 28;

[[gnu::target_clones("avx2", "default")]] void SmoothRow(const std::uint8_t* padded, int width,
                                                         std::int16_t* out) {
  const std::uint8_t* p = padded + 3;
  for (int x = 0; x < width; ++x) {
    out[x] =
        static_cast<std::int16_t>(kTap0 * (p[x - 3] + p[x + 3]) + kTap1 * (p[x - 2] + p[x + 2]) +
                                  kTap2 * (p[x - 1] + p[x + 1]) + kTap3 * p[x]);
  }
}

[[gnu::target_clones("avx2", "default")]] void SmoothColumn(
    const std::int16_t* r0, const std::int16_t* r1, const std::int16_t* r2, const std::int16_t* r3,
    const std::int16_t* r4, const std::int16_t* r5, const std::int16_t* r6, int width,
    std::uint8_t* out) {
  for (int x = 0; x < width; ++x) {
    const int sum =
        kTap0 * (r0[x] + r6[x]) + kTap1 * (r1[x] + r5[x]) + kTap2 * (r2[x] + r4[x]) + kTap3 * r3[x];
    out[x] = static_cast<std::uint8_t>((sum + (1 << 13)) >> 14);
  }
}

int Reflect101(int i, int n) { return i < 0 ? -i : (i >= n ? 2 * n - 2 - i : i); }

}  // namespace

void SmoothForDescriptor(const cv::Mat& image, cv::Mat* smoothed) {
  CV_Assert(image.type() == CV_8UC1);
  const int width = image.cols;
  const int height = image.rows;
  if (width < 4 || height < 4) {  // reflection needs 3 pixels beyond the first
    cv::GaussianBlur(image, *smoothed, cv::Size(7, 7), 2.0, 2.0, cv::BORDER_REFLECT_101);
    return;
  }
  smoothed->create(image.size(), CV_8UC1);
  std::vector<std::uint8_t> padded(width + 6);
  std::vector<std::int16_t> ring(7 * static_cast<std::size_t>(width));
  auto row_of = [&](int y) { return ring.data() + static_cast<std::size_t>((y + 7) % 7) * width; };
  auto smooth_row = [&](int y) {
    const std::uint8_t* src = image.ptr<std::uint8_t>(Reflect101(y, height));
    std::copy(src, src + width, padded.begin() + 3);
    for (int i = 1; i <= 3; ++i) {
      padded[3 - i] = src[i];
      padded[width + 2 + i] = src[width - 1 - i];
    }
    SmoothRow(padded.data(), width, row_of(y));
  };
  for (int y = -3; y < 3; ++y) smooth_row(y);
  for (int y = 0; y < height; ++y) {
    smooth_row(y + 3);
    SmoothColumn(row_of(y - 3), row_of(y - 2), row_of(y - 1), row_of(y), row_of(y + 1),
                 row_of(y + 2), row_of(y + 3), width, smoothed->ptr<std::uint8_t>(y));
  }
}

RbriefPattern::RbriefPattern(int patch_size) {
  const auto table = OrbPattern31();
  const double scale = patch_size / 31.0;
  xs_.reserve(table.size() / 2);
  ys_.reserve(table.size() / 2);
  for (std::size_t i = 0; i < table.size(); i += 2) {
    const float x = static_cast<float>(std::lround(table[i] * scale));
    const float y = static_cast<float>(std::lround(table[i + 1] * scale));
    xs_.push_back(x);
    ys_.push_back(y);
    max_radius_ = std::max(max_radius_, std::hypot(double(x), double(y)));
  }
}

Descriptor RbriefPattern::Compute(const cv::Mat& smoothed, cv::Point center,
                                  float angle_deg) const {
  // Same float arithmetic and rounding (to nearest, ties to even, as cvRound) as OpenCV's
  // ORB, so the sampled pixels coincide: x' = x cos - y sin, y' = x sin + y cos.
  const float angle = angle_deg * static_cast<float>(std::numbers::pi / 180.0);
  const float a = static_cast<float>(std::cos(static_cast<double>(angle)));
  const float b = static_cast<float>(std::sin(static_cast<double>(angle)));
  const int n = static_cast<int>(xs_.size());
  std::array<int, 2 * kOrbDescriptorBits> ix;
  std::array<int, 2 * kOrbDescriptorBits> iy;
  int i = 0;
#if defined(__SSE2__)
  const __m128 va = _mm_set1_ps(a);
  const __m128 vb = _mm_set1_ps(b);
  for (; i + 4 <= n; i += 4) {
    const __m128 px = _mm_loadu_ps(xs_.data() + i);
    const __m128 py = _mm_loadu_ps(ys_.data() + i);
    const __m128 rx = _mm_sub_ps(_mm_mul_ps(px, va), _mm_mul_ps(py, vb));
    const __m128 ry = _mm_add_ps(_mm_mul_ps(px, vb), _mm_mul_ps(py, va));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(ix.data() + i), _mm_cvtps_epi32(rx));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(iy.data() + i), _mm_cvtps_epi32(ry));
  }
#endif
  for (; i < n; ++i) {
    const float rx = xs_[i] * a - ys_[i] * b;
    const float ry = xs_[i] * b + ys_[i] * a;
    ix[i] = cvRound(rx);
    iy[i] = cvRound(ry);
  }
  const std::ptrdiff_t step = static_cast<std::ptrdiff_t>(smoothed.step1());
  const std::uint8_t* c = smoothed.ptr<std::uint8_t>(center.y) + center.x;
  auto sample = [&](int k) { return c[iy[k] * step + ix[k]]; };
  Descriptor desc;
  for (int byte = 0; byte < 32; ++byte) {
    int value = 0;
    for (int bit = 0; bit < 8; ++bit) {
      const int k = 2 * (8 * byte + bit);
      value |= (sample(k) < sample(k + 1) ? 1 : 0) << bit;
    }
    desc.bytes[byte] = static_cast<std::uint8_t>(value);
  }
  return desc;
}

}  // namespace pkslam
