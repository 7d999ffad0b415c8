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

OrientationDisc::OrientationDisc(int half_patch)
    : half_(half_patch), u_max_(CircularPatchHalfWidths(half_patch)) {
  // The disc rows in chunks of 16 pixels starting at -half, the last one moved back to end at
  // +half (never reading beyond the disc's square) with its overlap weighted 0.
  const int width = 2 * half_ + 1;
  if (width >= kChunk) {
    for (int start = -half_; start <= half_; start += kChunk) {
      chunk_start_.push_back(std::min(start, half_ + 1 - kChunk));
    }
  }
  const std::size_t n_chunks = chunk_start_.size();
  u_weight_.assign((half_ + 1) * n_chunks * kChunk, 0);
  v_weight_.assign(u_weight_.size(), 0);
  for (int v = 0; v <= half_; ++v) {
    int covered = -half_;  // first u not yet weighted in this row
    for (std::size_t k = 0; k < n_chunks; ++k) {
      for (int lane = 0; lane < kChunk; ++lane) {
        const int u = chunk_start_[k] + lane;
        if (u < covered || std::abs(u) > u_max_[v]) continue;
        const std::size_t index = (v * n_chunks + k) * kChunk + lane;
        u_weight_[index] = static_cast<std::int16_t>(u);
        v_weight_[index] = static_cast<std::int16_t>(v);
      }
      covered = chunk_start_[k] + kChunk;
    }
  }
}

float OrientationDisc::Angle(const cv::Mat& image, cv::Point center) const {
  const std::ptrdiff_t step = static_cast<std::ptrdiff_t>(image.step1());
  const std::uint8_t* c = image.ptr<std::uint8_t>(center.y) + center.x;
  int m_10 = 0;
  int m_01 = 0;
#if defined(__SSE2__)
  if (!chunk_start_.empty()) {
    // Rows v and -v together: u * (below + above) feeds m_10, v * (below - above) m_01;
    // pmaddwd multiplies the 16-bit lanes by the weights and sums pairs into 32 bits.
    const std::size_t n_chunks = chunk_start_.size();
    const __m128i zero = _mm_setzero_si128();
    __m128i acc_10 = zero;
    __m128i acc_01 = zero;
    auto weights = [&](const std::vector<std::int16_t>& w, int v, std::size_t k, int half) {
      return _mm_loadu_si128(
          reinterpret_cast<const __m128i*>(w.data() + (v * n_chunks + k) * kChunk + 8 * half));
    };
    for (int v = 0; v <= half_; ++v) {
      const std::uint8_t* below = c + v * step;
      const std::uint8_t* above = c - v * step;
      for (std::size_t k = 0; k < n_chunks; ++k) {
        const __m128i bb =
            _mm_loadu_si128(reinterpret_cast<const __m128i*>(below + chunk_start_[k]));
        const __m128i aa =
            _mm_loadu_si128(reinterpret_cast<const __m128i*>(above + chunk_start_[k]));
        const __m128i b_lo = _mm_unpacklo_epi8(bb, zero);
        const __m128i b_hi = _mm_unpackhi_epi8(bb, zero);
        if (v == 0) {  // the centre row counts once
          acc_10 = _mm_add_epi32(acc_10, _mm_madd_epi16(b_lo, weights(u_weight_, 0, k, 0)));
          acc_10 = _mm_add_epi32(acc_10, _mm_madd_epi16(b_hi, weights(u_weight_, 0, k, 1)));
          continue;
        }
        const __m128i a_lo = _mm_unpacklo_epi8(aa, zero);
        const __m128i a_hi = _mm_unpackhi_epi8(aa, zero);
        acc_10 = _mm_add_epi32(
            acc_10, _mm_madd_epi16(_mm_add_epi16(b_lo, a_lo), weights(u_weight_, v, k, 0)));
        acc_10 = _mm_add_epi32(
            acc_10, _mm_madd_epi16(_mm_add_epi16(b_hi, a_hi), weights(u_weight_, v, k, 1)));
        acc_01 = _mm_add_epi32(
            acc_01, _mm_madd_epi16(_mm_sub_epi16(b_lo, a_lo), weights(v_weight_, v, k, 0)));
        acc_01 = _mm_add_epi32(
            acc_01, _mm_madd_epi16(_mm_sub_epi16(b_hi, a_hi), weights(v_weight_, v, k, 1)));
      }
    }
    alignas(16) std::array<int, 4> lanes{};
    _mm_store_si128(reinterpret_cast<__m128i*>(lanes.data()), acc_10);
    m_10 = lanes[0] + lanes[1] + lanes[2] + lanes[3];
    _mm_store_si128(reinterpret_cast<__m128i*>(lanes.data()), acc_01);
    m_01 = lanes[0] + lanes[1] + lanes[2] + lanes[3];
  } else
#endif
  {
    for (int u = -half_; u <= half_; ++u) m_10 += u * c[u];
    for (int v = 1; v <= half_; ++v) {
      const std::uint8_t* below = c + v * step;
      const std::uint8_t* above = c - v * step;
      int diff_sum = 0;
      for (int u = -u_max_[v]; u <= u_max_[v]; ++u) {
        diff_sum += below[u] - above[u];
        m_10 += u * (below[u] + above[u]);
      }
      m_01 += v * diff_sum;
    }
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
// are written for the auto-vectoriser and compiled twice, for AVX2 and for the baseline,
// chosen at run time (explicit dispatch rather than ifunc target_clones, whose resolvers run
// before sanitizer runtimes are initialised).
constexpr int kTap0 = 9, kTap1 = 17, kTap2 = 24, kTap3 = 28;

[[gnu::always_inline]] inline void SmoothRowBody(const std::uint8_t* padded, int width,
                                                 std::int16_t* out) {
  const std::uint8_t* p = padded + 3;
  for (int x = 0; x < width; ++x) {
    out[x] =
        static_cast<std::int16_t>(kTap0 * (p[x - 3] + p[x + 3]) + kTap1 * (p[x - 2] + p[x + 2]) +
                                  kTap2 * (p[x - 1] + p[x + 1]) + kTap3 * p[x]);
  }
}

// rows[0..6]: the smoothed rows y-3 .. y+3.
[[gnu::always_inline]] inline void SmoothColumnBody(const std::int16_t* const* rows, int width,
                                                    std::uint8_t* out) {
  const std::int16_t* r0 = rows[0];
  const std::int16_t* r1 = rows[1];
  const std::int16_t* r2 = rows[2];
  const std::int16_t* r3 = rows[3];
  const std::int16_t* r4 = rows[4];
  const std::int16_t* r5 = rows[5];
  const std::int16_t* r6 = rows[6];
  for (int x = 0; x < width; ++x) {
    const int sum =
        kTap0 * (r0[x] + r6[x]) + kTap1 * (r1[x] + r5[x]) + kTap2 * (r2[x] + r4[x]) + kTap3 * r3[x];
    out[x] = static_cast<std::uint8_t>((sum + (1 << 13)) >> 14);
  }
}

using SmoothRowFn = void (*)(const std::uint8_t*, int, std::int16_t*);
using SmoothColumnFn = void (*)(const std::int16_t* const*, int, std::uint8_t*);

void SmoothRowBaseline(const std::uint8_t* padded, int width, std::int16_t* out) {
  SmoothRowBody(padded, width, out);
}
void SmoothColumnBaseline(const std::int16_t* const* rows, int width, std::uint8_t* out) {
  SmoothColumnBody(rows, width, out);
}

#if defined(__x86_64__) && defined(__GNUC__)
[[gnu::target("avx2")]] void SmoothRowAvx2(const std::uint8_t* padded, int width,
                                           std::int16_t* out) {
  SmoothRowBody(padded, width, out);
}
[[gnu::target("avx2")]] void SmoothColumnAvx2(const std::int16_t* const* rows, int width,
                                              std::uint8_t* out) {
  SmoothColumnBody(rows, width, out);
}
bool HasAvx2() { return __builtin_cpu_supports("avx2"); }
#else
void SmoothRowAvx2(const std::uint8_t* padded, int width, std::int16_t* out) {
  SmoothRowBody(padded, width, out);
}
void SmoothColumnAvx2(const std::int16_t* const* rows, int width, std::uint8_t* out) {
  SmoothColumnBody(rows, width, out);
}
bool HasAvx2() { return false; }
#endif

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
  const bool avx2 = HasAvx2();
  const SmoothRowFn smooth_row_fn = avx2 ? SmoothRowAvx2 : SmoothRowBaseline;
  const SmoothColumnFn smooth_column = avx2 ? SmoothColumnAvx2 : SmoothColumnBaseline;
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
    smooth_row_fn(padded.data(), width, row_of(y));
  };
  for (int y = -3; y < 3; ++y) smooth_row(y);
  for (int y = 0; y < height; ++y) {
    smooth_row(y + 3);
    const std::int16_t* rows[7];
    for (int k = 0; k < 7; ++k) rows[k] = row_of(y - 3 + k);
    smooth_column(rows, width, smoothed->ptr<std::uint8_t>(y));
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
  const std::ptrdiff_t step = static_cast<std::ptrdiff_t>(smoothed.step1());
  // Memory offset of every rotated test point from the centre.
  std::array<int, 2 * kOrbDescriptorBits> offset;
  int i = 0;
#if defined(__SSE2__)
  // round(y) * step + round(x) in float is exact while |offset| < 2^24.
  if (step < (1 << 19)) {
    const __m128 va = _mm_set1_ps(a);
    const __m128 vb = _mm_set1_ps(b);
    const __m128 vstep = _mm_set1_ps(static_cast<float>(step));
    for (; i + 4 <= n; i += 4) {
      const __m128 px = _mm_loadu_ps(xs_.data() + i);
      const __m128 py = _mm_loadu_ps(ys_.data() + i);
      const __m128 rx = _mm_sub_ps(_mm_mul_ps(px, va), _mm_mul_ps(py, vb));
      const __m128 ry = _mm_add_ps(_mm_mul_ps(px, vb), _mm_mul_ps(py, va));
      const __m128 ix = _mm_cvtepi32_ps(_mm_cvtps_epi32(rx));
      const __m128 iy = _mm_cvtepi32_ps(_mm_cvtps_epi32(ry));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(offset.data() + i),
                       _mm_cvtps_epi32(_mm_add_ps(_mm_mul_ps(iy, vstep), ix)));
    }
  }
#endif
  for (; i < n; ++i) {
    const float rx = xs_[i] * a - ys_[i] * b;
    const float ry = xs_[i] * b + ys_[i] * a;
    offset[i] = static_cast<int>(cvRound(ry) * step + cvRound(rx));
  }
  const std::uint8_t* c = smoothed.ptr<std::uint8_t>(center.y) + center.x;
  // Gather both samples of every test, then compare them 16 tests at a time.
  std::array<std::uint8_t, kOrbDescriptorBits> first;
  std::array<std::uint8_t, kOrbDescriptorBits> second;
  for (std::size_t t = 0; t < kOrbDescriptorBits; ++t) {
    first[t] = c[offset[2 * t]];
    second[t] = c[offset[2 * t + 1]];
  }
  Descriptor desc;
#if defined(__SSE2__)
  const __m128i flip = _mm_set1_epi8(static_cast<char>(0x80));  // unsigned -> signed order
  for (std::size_t t = 0; t < kOrbDescriptorBits; t += 16) {
    const __m128i f =
        _mm_xor_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(first.data() + t)), flip);
    const __m128i g =
        _mm_xor_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(second.data() + t)), flip);
    const int bits = _mm_movemask_epi8(_mm_cmplt_epi8(f, g));  // bit i: test t + i
    desc.bytes[t / 8] = static_cast<std::uint8_t>(bits & 0xff);
    desc.bytes[t / 8 + 1] = static_cast<std::uint8_t>(bits >> 8);
  }
#else
  for (std::size_t byte = 0; byte < 32; ++byte) {
    int value = 0;
    for (int bit = 0; bit < 8; ++bit) {
      value |= (first[8 * byte + bit] < second[8 * byte + bit] ? 1 : 0) << bit;
    }
    desc.bytes[byte] = static_cast<std::uint8_t>(value);
  }
#endif
  return desc;
}

}  // namespace pkslam
