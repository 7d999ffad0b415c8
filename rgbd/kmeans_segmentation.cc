#include "rgbd/kmeans_segmentation.h"

#include <algorithm>
#include <limits>
#include <opencv2/core.hpp>
#include <random>

#include "core/util/error.h"

namespace pkslam::rgbd {

void KMeansOptions::Check() const {
  PKSLAM_CHECK_OPTION(clusters >= 1, "kmeans clusters", "{}", clusters);
  PKSLAM_CHECK_OPTION(geometry_weight > 0, "kmeans geometry_weight", "{}", geometry_weight);
  PKSLAM_CHECK_OPTION(stride >= 1, "kmeans stride", "{}", stride);
  PKSLAM_CHECK_OPTION(iterations >= 1, "kmeans iterations", "{}", iterations);
}

namespace {

int NearestCentre(const float* x, const cv::Mat& centres) {
  int best = 0;
  float best_d = std::numeric_limits<float>::max();
  for (int c = 0; c < centres.rows; ++c) {
    const float* m = centres.ptr<float>(c);
    float d = 0;
    for (int k = 0; k < 6; ++k) d += (x[k] - m[k]) * (x[k] - m[k]);
    if (d < best_d) {
      best_d = d;
      best = c;
    }
  }
  return best;
}

}  // namespace

Segmentation SegmentKMeans(const ColouredCloud& cloud, cv::Size size,
                           const KMeansOptions& options) {
  options.Check();
  Segmentation seg;
  seg.labels = cv::Mat(size, CV_32SC1, cv::Scalar(-1));
  const int n = static_cast<int>(cloud.size());
  if (n == 0) return seg;

  // Features, normalised per column to [0, 1].
  cv::Mat features(n, 6, CV_32F);
  float lo[6], hi[6];
  std::fill(lo, lo + 6, std::numeric_limits<float>::max());
  std::fill(hi, hi + 6, std::numeric_limits<float>::lowest());
  for (int i = 0; i < n; ++i) {
    float* f = features.ptr<float>(i);
    const cv::Vec3b& bgr = cloud.colours[i];
    f[0] = bgr[2];
    f[1] = bgr[1];
    f[2] = bgr[0];
    f[3] = cloud.points[i].x();
    f[4] = cloud.points[i].y();
    f[5] = cloud.points[i].z();
    for (int k = 0; k < 6; ++k) {
      lo[k] = std::min(lo[k], f[k]);
      hi[k] = std::max(hi[k], f[k]);
    }
  }
  for (int i = 0; i < n; ++i) {
    float* f = features.ptr<float>(i);
    for (int k = 0; k < 6; ++k) {
      const float range = hi[k] - lo[k];
      f[k] = range > 0 ? (f[k] - lo[k]) / range : 0.0f;
      if (k >= 3) f[k] *= static_cast<float>(options.geometry_weight);
    }
  }

  // The clustered subset: points on the stride grid.
  const int w = size.width;
  std::vector<int> subset;
  for (int i = 0; i < n; ++i) {
    const int pixel = cloud.pixels[i];
    if ((pixel % w) % options.stride == 0 && (pixel / w) % options.stride == 0) subset.push_back(i);
  }
  const int k = std::min<int>(options.clusters, static_cast<int>(subset.size()));
  seg.count = k;
  if (k == 0) return seg;
  cv::Mat samples(static_cast<int>(subset.size()), 6, CV_32F);
  for (std::size_t j = 0; j < subset.size(); ++j) {
    features.row(subset[j]).copyTo(samples.row(static_cast<int>(j)));
  }

  // Initial centres: k distinct samples drawn at random; initial labels: nearest centre.
  std::mt19937_64 rng(options.seed);
  std::vector<int> pool(subset.size());
  for (std::size_t j = 0; j < pool.size(); ++j) pool[j] = static_cast<int>(j);
  cv::Mat centres(k, 6, CV_32F);
  for (int c = 0; c < k; ++c) {
    std::uniform_int_distribution<std::size_t> pick(c, pool.size() - 1);
    std::swap(pool[c], pool[pick(rng)]);
    samples.row(pool[c]).copyTo(centres.row(c));
  }
  cv::Mat labels(samples.rows, 1, CV_32S);
  for (int j = 0; j < samples.rows; ++j) {
    labels.at<int>(j) = NearestCentre(samples.ptr<float>(j), centres);
  }
  cv::kmeans(
      samples, k, labels,
      cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, options.iterations, 1e-4),
      1, cv::KMEANS_USE_INITIAL_LABELS, centres);

  int* out = seg.labels.ptr<int>(0);
  for (std::size_t j = 0; j < subset.size(); ++j) {
    out[cloud.pixels[subset[j]]] = labels.at<int>(static_cast<int>(j));
  }
  if (options.stride > 1) {
    for (int i = 0; i < n; ++i) {
      const int pixel = cloud.pixels[i];
      if (out[pixel] < 0) out[pixel] = NearestCentre(features.ptr<float>(i), centres);
    }
  }
  return seg;
}

}  // namespace pkslam::rgbd
