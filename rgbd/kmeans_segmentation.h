// The K-Means baseline segmentation of seed 001 (section 3-1-1): every valid-depth pixel is a
// 6-D sample (R, G, B, x, y, z); each column is normalised to [0, 1] and the coordinate
// columns are multiplied by a weight > 1 so position counts more than colour; cv::kmeans
// clusters them into K segments. Initial centres are K samples drawn with our own seeded
// generator (OpenCV's own seeding uses its global RNG).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "rgbd/depth_cloud.h"
#include "rgbd/region_growing.h"

namespace pkslam::rgbd {

struct KMeansOptions {
  int clusters = 400;            // K
  double geometry_weight = 2.0;  // multiplies the normalised x, y, z columns
  int stride = 2;                // cluster every stride-th pixel; the rest join the nearest centre
  int iterations = 10;           // Lloyd iterations
  std::uint64_t seed = 1;

  void Check() const;
};

// Labels (image of `size`) for the pixels of `cloud` (cloud.pixels index the image);
// pixels without a point stay -1. Segmentation::count = number of clusters (some may be empty).
Segmentation SegmentKMeans(const ColouredCloud& cloud, cv::Size size, const KMeansOptions& options);

}  // namespace pkslam::rgbd
