#include "core/features/stereo_matcher.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "core/features/orb_extractor.h"
#include "core/util/error.h"

namespace pkslam {
namespace {

// n / d rounded to nearest, halves away from zero (d > 0), as std::lround(double(n) / d).
int RoundedDivision(int n, int d) { return n >= 0 ? (n + d / 2) / d : -((-n + d / 2) / d); }

// Row stride of the padded right strip copy (room for a 16-byte load at every shift).
constexpr int kStripStride = 64;

// Reused buffers of SadProfile.
struct SadScratch {
  std::vector<int> left_window;
  std::vector<int> column_sums;
#if defined(__SSE2__)
  std::vector<std::int16_t> left_rows;    // side rows of 16 lanes, zero beyond the window
  std::vector<std::uint8_t> right_strip;  // side rows of kStripStride bytes
  __m128i lane_mask[2] = {};              // lanes inside the window
#endif
};

// SAD of the (2w+1)^2 left window centred at `cl` against the right windows centred at
// (cr.x + s, cr.y), s = -radius..radius (costs[s + radius]), after adding to the left window
// the brightness offset `normalization` asks for. The left window and the right column sums
// are gathered once for all shifts.
void SadProfile(const cv::Mat& left, cv::Point cl, const cv::Mat& right, cv::Point cr, int w,
                int radius, SadNormalization normalization, SadScratch* scratch,
                std::vector<int>* costs) {
  const int side = 2 * w + 1;
  const int strip = side + 2 * radius;
  std::vector<int>& window = scratch->left_window;
  window.resize(static_cast<std::size_t>(side) * side);
  int left_sum = 0;
  for (int dy = 0; dy < side; ++dy) {
    const std::uint8_t* row = left.ptr<std::uint8_t>(cl.y - w + dy) + cl.x - w;
    for (int dx = 0; dx < side; ++dx) {
      window[dy * side + dx] = row[dx];
      left_sum += row[dx];
    }
  }
  std::vector<int>& column_sums = scratch->column_sums;
  column_sums.assign(strip, 0);
  for (int dy = 0; dy < side; ++dy) {
    const std::uint8_t* row = right.ptr<std::uint8_t>(cr.y - w + dy) + cr.x - radius - w;
    for (int c = 0; c < strip; ++c) column_sums[c] += row[c];
  }
#if defined(__SSE2__)
  const bool simd = side <= 16 && strip + 16 <= kStripStride;
  if (simd) {
    scratch->left_rows.assign(static_cast<std::size_t>(side) * 16, 0);
    scratch->right_strip.assign(static_cast<std::size_t>(side) * kStripStride, 0);
    for (int dy = 0; dy < side; ++dy) {
      for (int dx = 0; dx < side; ++dx) {
        scratch->left_rows[dy * 16 + dx] = static_cast<std::int16_t>(window[dy * side + dx]);
      }
      const std::uint8_t* row = right.ptr<std::uint8_t>(cr.y - w + dy) + cr.x - radius - w;
      std::copy(row, row + strip, scratch->right_strip.begin() + dy * kStripStride);
    }
    alignas(16) std::array<std::int16_t, 16> mask{};
    for (int lane = 0; lane < side; ++lane) mask[lane] = -1;
    scratch->lane_mask[0] = _mm_load_si128(reinterpret_cast<const __m128i*>(mask.data()));
    scratch->lane_mask[1] = _mm_load_si128(reinterpret_cast<const __m128i*>(mask.data() + 8));
  }
#endif
  const int left_centre = left.at<std::uint8_t>(cl);
  int right_sum = 0;
  for (int c = 0; c < side; ++c) right_sum += column_sums[c];
  for (int k = 0; k <= 2 * radius; ++k) {
    if (k > 0) right_sum += column_sums[k + side - 1] - column_sums[k - 1];
    int offset = 0;
    if (normalization == SadNormalization::kWindowMean) {
      offset = RoundedDivision(right_sum - left_sum, side * side);
    } else if (normalization == SadNormalization::kCentrePixel) {
      offset = int(right.at<std::uint8_t>(cr.y, cr.x - radius + k)) - left_centre;
    }
    int sad = 0;
#if defined(__SSE2__)
    if (simd) {
      // 16 lanes per row: the left row (padded with zeros) plus the offset against the right
      // strip from column k; lanes beyond the window are masked out before summing.
      const __m128i off = _mm_set1_epi16(static_cast<short>(offset));
      const __m128i zero = _mm_setzero_si128();
      const __m128i ones = _mm_set1_epi16(1);
      __m128i acc = zero;
      for (int dy = 0; dy < side; ++dy) {
        const __m128i r8 = _mm_loadu_si128(
            reinterpret_cast<const __m128i*>(scratch->right_strip.data() + dy * kStripStride + k));
        const std::int16_t* l = scratch->left_rows.data() + dy * 16;
        const __m128i d_lo =
            _mm_sub_epi16(_mm_add_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(l)), off),
                          _mm_unpacklo_epi8(r8, zero));
        const __m128i d_hi = _mm_sub_epi16(
            _mm_add_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(l + 8)), off),
            _mm_unpackhi_epi8(r8, zero));
        const __m128i a_lo =
            _mm_and_si128(_mm_max_epi16(d_lo, _mm_sub_epi16(zero, d_lo)), scratch->lane_mask[0]);
        const __m128i a_hi =
            _mm_and_si128(_mm_max_epi16(d_hi, _mm_sub_epi16(zero, d_hi)), scratch->lane_mask[1]);
        acc = _mm_add_epi32(acc, _mm_madd_epi16(a_lo, ones));
        acc = _mm_add_epi32(acc, _mm_madd_epi16(a_hi, ones));
      }
      alignas(16) std::array<int, 4> lanes{};
      _mm_store_si128(reinterpret_cast<__m128i*>(lanes.data()), acc);
      sad = lanes[0] + lanes[1] + lanes[2] + lanes[3];
    } else
#endif
    {
      for (int dy = 0; dy < side; ++dy) {
        const std::uint8_t* r = right.ptr<std::uint8_t>(cr.y - w + dy) + cr.x - radius - w + k;
        const int* l = window.data() + dy * side;
        for (int dx = 0; dx < side; ++dx) sad += std::abs(l[dx] + offset - int(r[dx]));
      }
    }
    (*costs)[k] = sad;
  }
}

// Sub-pixel offset of the minimum from the costs at -1, 0, +1 (c0 the smallest), or nullopt
// when the costs are flat.
std::optional<double> SubpixelOffset(double c_minus, double c0, double c_plus, SubpixelFit fit) {
  if (fit == SubpixelFit::kParabola) {
    const double curvature = c_minus + c_plus - 2.0 * c0;
    if (curvature <= 0.0) return std::nullopt;
    return (c_minus - c_plus) / (2.0 * curvature);
  }
  // Two lines of opposite slope through the three costs (the shape of a SAD minimum).
  const double slope = std::max(c_minus, c_plus) - c0;
  if (slope <= 0.0) return std::nullopt;
  return (c_minus - c_plus) / (2.0 * slope);
}

}  // namespace

void StereoMatcherOptions::Check() const {
  PKSLAM_CHECK_OPTION(max_descriptor_distance >= 1 && max_descriptor_distance <= 257,
                      "max_descriptor_distance", "{}", max_descriptor_distance);
  PKSLAM_CHECK_OPTION(row_band_scale >= 0.0, "row_band_scale", "{}", row_band_scale);
  PKSLAM_CHECK_OPTION(octave_tolerance >= 0, "octave_tolerance", "{}", octave_tolerance);
  PKSLAM_CHECK_OPTION(min_depth_baselines > 0.0, "min_depth_baselines", "{}", min_depth_baselines);
  PKSLAM_CHECK_OPTION(sad_half_window >= 1, "sad_half_window", "{}", sad_half_window);
  PKSLAM_CHECK_OPTION(sad_search_radius >= 2, "sad_search_radius", "{}", sad_search_radius);
  PKSLAM_CHECK_OPTION(sad_outlier_factor > 0.0, "sad_outlier_factor", "{}", sad_outlier_factor);
}

StereoMatches MatchStereo(std::span<const cv::KeyPoint> left_keypoints,
                          std::span<const Descriptor> left_descriptors,
                          const ImagePyramid& left_pyramid,
                          std::span<const cv::KeyPoint> right_keypoints,
                          std::span<const Descriptor> right_descriptors,
                          const ImagePyramid& right_pyramid, double bf, double fx,
                          const StereoMatcherOptions& options) {
  options.Check();
  PKSLAM_CHECK(left_keypoints.size() == left_descriptors.size() &&
                   right_keypoints.size() == right_descriptors.size(),
               "keypoint and descriptor counts differ");
  PKSLAM_CHECK(left_pyramid.NumLevels() >= 1 &&
                   left_pyramid.NumLevels() == right_pyramid.NumLevels() &&
                   left_pyramid.levels[0].size() == right_pyramid.levels[0].size(),
               "stereo pyramids must have the same levels and image size");
  PKSLAM_CHECK(bf > 0.0 && fx > 0.0, "bf {} and fx {} must be positive", bf, fx);

  const int n_left = static_cast<int>(left_keypoints.size());
  const int n_levels = left_pyramid.NumLevels();
  StereoMatches out;
  out.u_right.assign(n_left, -1.0f);
  out.depth.assign(n_left, -1.0f);
  out.right_index.assign(n_left, -1);
  out.sad.assign(n_left, -1);

  // Right keypoints listed under every row their band covers, as one flat array
  // (row_start[y] .. row_start[y + 1] index into row_keypoints), in keypoint order.
  const int rows = left_pyramid.levels[0].rows;
  const int n_right = static_cast<int>(right_keypoints.size());
  std::vector<std::pair<int, int>> bands(n_right);
  std::vector<int> row_start(rows + 1, 0);
  for (int i = 0; i < n_right; ++i) {
    const cv::KeyPoint& kp = right_keypoints[i];
    PKSLAM_CHECK(kp.octave >= 0 && kp.octave < n_levels, "right octave {} out of range", kp.octave);
    const double r = options.row_band_scale * right_pyramid.ScaleY(kp.octave);
    bands[i] = {std::max(0, static_cast<int>(std::floor(kp.pt.y - r))),
                std::min(rows - 1, static_cast<int>(std::ceil(kp.pt.y + r)))};
    for (int y = bands[i].first; y <= bands[i].second; ++y) ++row_start[y + 1];
  }
  for (int y = 0; y < rows; ++y) row_start[y + 1] += row_start[y];
  std::vector<int> row_keypoints(row_start[rows]);
  std::vector<int> fill(row_start.begin(), row_start.end() - 1);
  for (int i = 0; i < n_right; ++i) {
    for (int y = bands[i].first; y <= bands[i].second; ++y) row_keypoints[fill[y]++] = i;
  }

  const double min_disparity = 0.0;
  const double max_disparity = fx / options.min_depth_baselines;  // bf / (min_depth * b)
  const int w = options.sad_half_window;
  const int radius = options.sad_search_radius;
  std::vector<int> costs(2 * radius + 1);
  SadScratch scratch;
  std::vector<std::pair<int, int>> sad_and_index;
  sad_and_index.reserve(n_left);

  for (int il = 0; il < n_left; ++il) {
    const cv::KeyPoint& kl = left_keypoints[il];
    const int level = kl.octave;
    PKSLAM_CHECK(level >= 0 && level < n_levels, "left octave {} out of range", level);
    const int row = static_cast<int>(kl.pt.y);
    if (row < 0 || row >= rows) continue;
    const double u_left = kl.pt.x;
    const double min_u = u_left - max_disparity;
    const double max_u = u_left - min_disparity;
    if (max_u < 0.0) continue;

    // Best descriptor among right keypoints of a neighbouring octave in the disparity range.
    int best_distance = options.max_descriptor_distance;
    int best_right = -1;
    for (int c = row_start[row]; c < row_start[row + 1]; ++c) {
      const int ir = row_keypoints[c];
      const cv::KeyPoint& kr = right_keypoints[ir];
      if (std::abs(kr.octave - level) > options.octave_tolerance) continue;
      if (kr.pt.x < min_u || kr.pt.x > max_u) continue;
      const int d = HammingDistance(left_descriptors[il], right_descriptors[ir]);
      if (d < best_distance) {
        best_distance = d;
        best_right = ir;
      }
    }
    if (best_right < 0) continue;

    // SAD refinement on the left keypoint's level around the matched right position.
    const cv::Mat& left_image = left_pyramid.levels[level];
    const cv::Mat& right_image = right_pyramid.levels[level];
    const int xl = static_cast<int>(std::lround(left_pyramid.ToLevelX(level, u_left)));
    const int yl = static_cast<int>(std::lround(left_pyramid.ToLevelY(level, kl.pt.y)));
    const int xr0 = static_cast<int>(
        std::lround(right_pyramid.ToLevelX(level, right_keypoints[best_right].pt.x)));
    if (yl - w < 0 || yl + w >= left_image.rows || yl + w >= right_image.rows || xl - w < 0 ||
        xl + w >= left_image.cols || xr0 - radius - w < 0 || xr0 + radius + w >= right_image.cols) {
      continue;
    }
    SadProfile(left_image, {xl, yl}, right_image, {xr0, yl}, w, radius, options.sad_normalization,
               &scratch, &costs);
    int best_cost = std::numeric_limits<int>::max();
    int best_shift = 0;
    for (int shift = -radius; shift <= radius; ++shift) {
      if (costs[shift + radius] < best_cost) {
        best_cost = costs[shift + radius];
        best_shift = shift;
      }
    }
    if (best_shift == -radius || best_shift == radius) continue;  // minimum not bracketed

    const std::optional<double> delta =
        SubpixelOffset(costs[best_shift + radius - 1], costs[best_shift + radius],
                       costs[best_shift + radius + 1], options.subpixel_fit);
    if (!delta || *delta < -1.0 || *delta > 1.0) continue;

    double u_right = right_pyramid.ToBaseX(level, xr0 + best_shift + *delta);
    double disparity = u_left - u_right;
    if (disparity < min_disparity || disparity >= max_disparity) continue;
    if (disparity <= 0.0) {  // at infinity: keep a tiny disparity so depth stays finite
      disparity = 0.01;
      u_right = u_left - disparity;
    }
    out.u_right[il] = static_cast<float>(u_right);
    out.depth[il] = static_cast<float>(bf / disparity);
    out.right_index[il] = best_right;
    out.sad[il] = best_cost;
    sad_and_index.emplace_back(best_cost, il);
  }

  // Drop the matches whose SAD is far above the median (kept at equality, unlike ORB-SLAM,
  // so that a median of 0 on noise-free images does not reject everything).
  if (!sad_and_index.empty()) {
    std::sort(sad_and_index.begin(), sad_and_index.end());
    const int median = sad_and_index[sad_and_index.size() / 2].first;
    const double threshold = options.sad_outlier_factor * median;
    for (const auto& [cost, il] : sad_and_index) {
      if (cost <= threshold) continue;
      out.u_right[il] = -1.0f;
      out.depth[il] = -1.0f;
      out.right_index[il] = -1;
      out.sad[il] = -1;
    }
  }
  out.num_matches = static_cast<int>(
      std::count_if(out.depth.begin(), out.depth.end(), [](float d) { return d > 0.0f; }));
  return out;
}

StereoMatches MatchStereo(const OrbFeatures& left, const OrbFeatures& right, double bf, double fx,
                          const StereoMatcherOptions& options) {
  return MatchStereo(left.keypoints, left.descriptors, left.pyramid, right.keypoints,
                     right.descriptors, right.pyramid, bf, fx, options);
}

}  // namespace pkslam
