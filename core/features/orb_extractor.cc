#include "core/features/orb_extractor.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <exception>
#include <opencv2/features2d.hpp>
#include <thread>

#include "core/features/quadtree_distribution.h"
#include "core/util/error.h"

namespace pkslam {
namespace {

// FAST's Bresenham circle has radius 3: it cannot fire closer than that to a region's edge.
constexpr int kFastRadius = 3;
constexpr int kFastMinRegion = 2 * kFastRadius + 1;

// Level-0 position of a level-`level` pixel, as stored in the output keypoints.
cv::Point2f BasePoint(const ImagePyramid& pyramid, int level, double x, double y) {
  return {static_cast<float>(pyramid.ToBaseX(level, x)),
          static_cast<float>(pyramid.ToBaseY(level, y))};
}

// Drops keypoints (region coordinates, region at `offset` in level `level`) outside the mask.
void ApplyMask(const cv::Mat& mask, const ImagePyramid& pyramid, int level, cv::Point offset,
               std::vector<cv::KeyPoint>* kps) {
  if (mask.empty()) return;
  std::erase_if(*kps, [&](const cv::KeyPoint& kp) {
    const cv::Point2f p = BasePoint(pyramid, level, kp.pt.x + offset.x, kp.pt.y + offset.y);
    const int x = std::clamp(static_cast<int>(std::lround(p.x)), 0, mask.cols - 1);
    const int y = std::clamp(static_cast<int>(std::lround(p.y)), 0, mask.rows - 1);
    return mask.at<std::uint8_t>(y, x) == 0;
  });
}

// True when max - min <= range over the image; stops at the first row that breaks it.
bool IntensityRangeWithin(const cv::Mat& image, int range) {
  int lo = 255;
  int hi = 0;
  for (int y = 0; y < image.rows; ++y) {
    const std::uint8_t* row = image.ptr<std::uint8_t>(y);
    for (int x = 0; x < image.cols; ++x) {
      lo = std::min<int>(lo, row[x]);
      hi = std::max<int>(hi, row[x]);
    }
    if (hi - lo > range) return false;
  }
  return true;
}

// The options after Check(), so that members built from them never see bad values.
const OrbOptions& Checked(const OrbOptions& options) {
  options.Check();
  return options;
}

}  // namespace

void OrbOptions::Check() const {
  PKSLAM_CHECK_OPTION(n_features >= 1, "n_features", "{}", n_features);
  PKSLAM_CHECK_OPTION(scale_factor > 1.0 && scale_factor <= 4.0, "scale_factor", "{}",
                      scale_factor);
  PKSLAM_CHECK_OPTION(n_levels >= 1 && n_levels <= 32, "n_levels", "{}", n_levels);
  PKSLAM_CHECK_OPTION(ini_th_fast >= 1 && ini_th_fast <= 254, "ini_th_fast", "{}", ini_th_fast);
  PKSLAM_CHECK_OPTION(min_th_fast >= 1 && min_th_fast <= ini_th_fast, "min_th_fast", "{}",
                      min_th_fast);
  PKSLAM_CHECK_OPTION(patch_size >= 7 && patch_size <= 127 && patch_size % 2 == 1, "patch_size",
                      "{}", patch_size);
  // The orientation disc (radius patch/2) and the rotated tests (radius MaxRadius) must stay
  // inside the level for every keypoint, which lies >= edge_threshold from the border.
  const int needed =
      std::max(patch_size / 2, static_cast<int>(std::ceil(RbriefPattern(patch_size).MaxRadius())));
  PKSLAM_CHECK_OPTION(edge_threshold >= needed && edge_threshold <= 255, "edge_threshold",
                      "{} (patch {} needs >= {})", edge_threshold, patch_size, needed);
  PKSLAM_CHECK_OPTION(cell_size >= 2 * kFastMinRegion, "cell_size", "{}", cell_size);
}

OrbExtractor::OrbExtractor(const OrbOptions& options)
    : options_(Checked(options)),
      orientation_(options.patch_size / 2),
      pattern_(options.patch_size) {
  const int n = options_.n_levels;
  scale_.resize(n);
  inv_scale_.resize(n);
  sigma2_.resize(n);
  inv_sigma2_.resize(n);
  for (int level = 0; level < n; ++level) {
    const double s = std::pow(options_.scale_factor, level);
    scale_[level] = static_cast<float>(s);
    inv_scale_[level] = static_cast<float>(1.0 / s);
    sigma2_[level] = static_cast<float>(s * s);
    inv_sigma2_[level] = static_cast<float>(1.0 / (s * s));
  }
  // Geometric series with ratio 1/scale_factor summing to n_features.
  const double f = 1.0 / options_.scale_factor;
  double wanted = options_.n_features * (1.0 - f) / (1.0 - std::pow(f, n));
  quota_.assign(n, 0);
  int assigned = 0;
  for (int level = 0; level + 1 < n; ++level) {
    quota_[level] = static_cast<int>(std::lround(wanted));
    assigned += quota_[level];
    wanted *= f;
  }
  quota_[n - 1] = std::max(options_.n_features - assigned, 0);
}

std::vector<cv::KeyPoint> OrbExtractor::DetectCandidates(const cv::Mat& level_image, int level,
                                                         const ImagePyramid& pyramid,
                                                         const cv::Mat& mask) const {
  // Detection region: FAST fires >= kFastRadius inside it, so keypoints end up at least
  // edge_threshold from the level's border.
  const int border = options_.edge_threshold - kFastRadius;
  const int width = level_image.cols - 2 * border;
  const int height = level_image.rows - 2 * border;
  std::vector<cv::KeyPoint> keypoints;
  if (width < kFastMinRegion || height < kFastMinRegion) return keypoints;
  const cv::Mat region = level_image(cv::Rect(border, border, width, height));
  const cv::Point offset(border, border);

  // One FAST pass at the high threshold over the whole region (equivalent to ORB-SLAM's
  // per-cell calls at that threshold, except that non-maximum suppression also looks across
  // cell borders), then the low threshold in the cells where nothing was kept.
  cv::FAST(region, keypoints, options_.ini_th_fast, /*nonmaxSuppression=*/true);
  ApplyMask(mask, pyramid, level, offset, &keypoints);

  // Cells as ORB-SLAM: about cell_size, stretched to tile the region; cell (i, j) owns the
  // detections in [j*w + 3, (j+1)*w + 3) x [i*h + 3, (i+1)*h + 3).
  const int n_cols = std::max(1, width / options_.cell_size);
  const int n_rows = std::max(1, height / options_.cell_size);
  const int cell_w = (width + n_cols - 1) / n_cols;
  const int cell_h = (height + n_rows - 1) / n_rows;
  std::vector<int> count(static_cast<std::size_t>(n_cols) * n_rows, 0);
  for (const cv::KeyPoint& kp : keypoints) {
    const int j = std::min((static_cast<int>(kp.pt.x) - kFastRadius) / cell_w, n_cols - 1);
    const int i = std::min((static_cast<int>(kp.pt.y) - kFastRadius) / cell_h, n_rows - 1);
    ++count[i * n_cols + j];
  }
  std::vector<cv::KeyPoint> cell_keypoints;
  for (int i = 0; i < n_rows; ++i) {
    for (int j = 0; j < n_cols; ++j) {
      if (count[i * n_cols + j] > 0) continue;
      const int x0 = j * cell_w;
      const int y0 = i * cell_h;
      const int w = std::min(cell_w + 2 * kFastRadius, width - x0);
      const int h = std::min(cell_h + 2 * kFastRadius, height - y0);
      if (w < kFastMinRegion || h < kFastMinRegion) continue;
      const cv::Mat cell = region(cv::Rect(x0, y0, w, h));
      // A FAST corner needs pixels more than the threshold above or below the centre: none
      // exists where the intensity range is within it (saturated or blank areas).
      if (IntensityRangeWithin(cell, options_.min_th_fast)) continue;
      cv::FAST(cell, cell_keypoints, options_.min_th_fast, true);
      for (cv::KeyPoint& kp : cell_keypoints) {
        kp.pt.x += static_cast<float>(x0);
        kp.pt.y += static_cast<float>(y0);
      }
      ApplyMask(mask, pyramid, level, offset, &cell_keypoints);
      keypoints.insert(keypoints.end(), cell_keypoints.begin(), cell_keypoints.end());
    }
  }
  return keypoints;
}

void OrbExtractor::ExtractLevel(int level, const ImagePyramid& pyramid, const cv::Mat& mask,
                                cv::Mat* smoothed, LevelResult* out) const {
  out->keypoints.clear();
  out->descriptors.clear();
  const cv::Mat& image = pyramid.levels[level];
  const std::vector<cv::KeyPoint> candidates = DetectCandidates(image, level, pyramid, mask);
  if (candidates.empty()) {
    smoothed->release();
    return;
  }
  const int border = options_.edge_threshold - kFastRadius;
  const cv::Size area(image.cols - 2 * border, image.rows - 2 * border);
  const std::vector<int> keep = DistributeQuadtree(candidates, area, quota_[level]);

  SmoothForDescriptor(image, smoothed);
  out->keypoints.reserve(keep.size());
  out->descriptors.reserve(keep.size());
  const float size = static_cast<float>(options_.patch_size) * scale_[level];
  for (int index : keep) {
    const cv::KeyPoint& candidate = candidates[index];
    const cv::Point p(static_cast<int>(candidate.pt.x) + border,
                      static_cast<int>(candidate.pt.y) + border);
    const float angle = orientation_.Angle(image, p);
    out->descriptors.push_back(pattern_.Compute(*smoothed, p, angle));
    out->keypoints.emplace_back(BasePoint(pyramid, level, p.x, p.y), size, angle,
                                candidate.response, level);
  }
}

void OrbExtractor::Extract(const cv::Mat& image, OrbFeatures* features, const cv::Mat& mask) const {
  ExtractImpl(image, mask, options_.parallel, features);
}

void OrbExtractor::ExtractImpl(const cv::Mat& image, const cv::Mat& mask, bool with_helper,
                               OrbFeatures* features) const {
  PKSLAM_CHECK(!image.empty() && image.type() == CV_8UC1,
               "ORB extraction needs a non-empty CV_8UC1 image (type {}, {}x{})", image.type(),
               image.cols, image.rows);
  PKSLAM_CHECK(mask.empty() || (mask.type() == CV_8UC1 && mask.size() == image.size()),
               "ORB mask must be CV_8UC1 of the image size");
  internal::CheckPyramidInput(image, options_.scale_factor, options_.n_levels);
  const int n = options_.n_levels;
  std::vector<LevelResult> results(n);
  ImagePyramid& pyramid = features->pyramid;
  std::vector<cv::Mat>& smoothed = features->smoothed;
  smoothed.resize(n);
  auto extract_level = [&](int level) {
    ExtractLevel(level, pyramid, mask, &smoothed[level], &results[level]);
  };

  if (!with_helper) {
    BuildImagePyramid(image, options_.scale_factor, n, &pyramid);
    for (int level = 0; level < n; ++level) extract_level(level);
  } else {
    // One helper thread and the caller take levels in order (largest first) from a shared
    // counter; a level is processed once the caller has resized it. `ready` (levels built,
    // or n + 1 after a failure) publishes the pyramid with release/acquire ordering.
    std::atomic<int> next{0};
    std::atomic<int> ready{0};
    auto take_levels = [&]() -> std::exception_ptr {
      try {
        for (int level = next.fetch_add(1); level < n; level = next.fetch_add(1)) {
          int built = ready.load(std::memory_order_acquire);
          while (built <= level) {
            ready.wait(built, std::memory_order_acquire);
            built = ready.load(std::memory_order_acquire);
          }
          if (built > n) return nullptr;  // the caller failed and will report it
          extract_level(level);
        }
      } catch (...) {
        return std::current_exception();
      }
      return nullptr;
    };
    std::exception_ptr helper_error;
    std::thread helper([&] { helper_error = take_levels(); });
    std::exception_ptr caller_error;
    try {
      BuildImagePyramid(image, options_.scale_factor, n, &pyramid, [&](int level) {
        ready.store(level + 1, std::memory_order_release);
        ready.notify_all();
      });
    } catch (...) {
      caller_error = std::current_exception();
      ready.store(n + 1, std::memory_order_release);
      ready.notify_all();
    }
    if (!caller_error) caller_error = take_levels();
    helper.join();
    if (caller_error) std::rethrow_exception(caller_error);
    if (helper_error) std::rethrow_exception(helper_error);
  }

  std::size_t total = 0;
  for (const LevelResult& r : results) total += r.keypoints.size();
  features->keypoints.clear();
  features->descriptors.clear();
  features->keypoints.reserve(total);
  features->descriptors.reserve(total);
  for (const LevelResult& r : results) {
    features->keypoints.insert(features->keypoints.end(), r.keypoints.begin(), r.keypoints.end());
    features->descriptors.insert(features->descriptors.end(), r.descriptors.begin(),
                                 r.descriptors.end());
  }
}

OrbFeatures OrbExtractor::Extract(const cv::Mat& image) const {
  OrbFeatures features;
  Extract(image, &features);
  return features;
}

void OrbExtractor::ExtractStereo(const cv::Mat& left, const cv::Mat& right,
                                 OrbFeatures* left_features, OrbFeatures* right_features) const {
  if (!options_.parallel) {
    Extract(left, left_features);
    Extract(right, right_features);
    return;
  }
  // One thread per image, each doing its levels in turn: two busy threads, as many as cores.
  std::exception_ptr right_error;
  std::thread right_thread([&] {
    try {
      ExtractImpl(right, cv::Mat(), /*with_helper=*/false, right_features);
    } catch (...) {
      right_error = std::current_exception();
    }
  });
  std::exception_ptr left_error;
  try {
    ExtractImpl(left, cv::Mat(), /*with_helper=*/false, left_features);
  } catch (...) {
    left_error = std::current_exception();
  }
  right_thread.join();
  if (left_error) std::rethrow_exception(left_error);
  if (right_error) std::rethrow_exception(right_error);
}

}  // namespace pkslam
