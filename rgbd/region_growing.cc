#include "rgbd/region_growing.h"

#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/util/error.h"

namespace pkslam::rgbd {

cv::Mat BgrToLab(const cv::Mat& bgr) {
  PKSLAM_CHECK(bgr.type() == CV_8UC3, "BgrToLab needs CV_8UC3, got type {}", bgr.type());
  cv::Mat unit;
  bgr.convertTo(unit, CV_32FC3, 1.0 / 255.0);
  cv::Mat lab;
  cv::cvtColor(unit, lab, cv::COLOR_BGR2Lab);
  return lab;
}

Segmentation SegmentRegionGrowing(const cv::Mat& lab, double threshold, const cv::Mat& mask) {
  PKSLAM_CHECK(lab.type() == CV_32FC3, "lab image must be CV_32FC3, got type {}", lab.type());
  PKSLAM_CHECK(mask.empty() || (mask.type() == CV_8UC1 && mask.size() == lab.size()),
               "mask must be CV_8UC1 of the image size");
  PKSLAM_CHECK_OPTION(threshold > 0, "lab_threshold", "{}", threshold);
  const int w = lab.cols;
  const int h = lab.rows;
  Segmentation seg;
  seg.labels = cv::Mat(h, w, CV_32SC1, cv::Scalar(-1));
  int* labels = seg.labels.ptr<int>(0);
  PKSLAM_CHECK(lab.isContinuous() && seg.labels.isContinuous(), "continuous images expected");
  const float* pixels = lab.ptr<float>(0);
  const std::uint8_t* allowed = mask.empty() ? nullptr : mask.ptr<std::uint8_t>(0);
  const float threshold2 = static_cast<float>(threshold * threshold);
  std::vector<int> stack;
  stack.reserve(static_cast<std::size_t>(w) * h);
  constexpr int kDu[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
  constexpr int kDv[8] = {-1, -1, -1, 0, 0, 1, 1, 1};

  for (int seed = 0; seed < w * h; ++seed) {
    if (labels[seed] >= 0 || (allowed != nullptr && allowed[seed] == 0)) continue;
    const int id = seg.count++;
    float mean[3] = {pixels[3 * seed], pixels[3 * seed + 1], pixels[3 * seed + 2]};
    int t = 0;  // pixels in the segment
    stack.clear();
    stack.push_back(seed);
    while (!stack.empty()) {
      const int p = stack.back();
      stack.pop_back();
      if (labels[p] >= 0) continue;
      const float* x = pixels + 3 * p;
      const float d0 = x[0] - mean[0], d1 = x[1] - mean[1], d2 = x[2] - mean[2];
      if (d0 * d0 + d1 * d1 + d2 * d2 >= threshold2) continue;
      labels[p] = id;
      ++t;
      const float step = 1.0f / static_cast<float>(t);  // Eq. 5 with t+1 = new count
      mean[0] += d0 * step;
      mean[1] += d1 * step;
      mean[2] += d2 * step;
      const int u = p % w;
      const int v = p / w;
      for (int k = 0; k < 8; ++k) {
        const int nu = u + kDu[k];
        const int nv = v + kDv[k];
        if (nu < 0 || nu >= w || nv < 0 || nv >= h) continue;
        const int q = nv * w + nu;
        if (labels[q] >= 0 || (allowed != nullptr && allowed[q] == 0)) continue;
        stack.push_back(q);
      }
    }
  }
  return seg;
}

}  // namespace pkslam::rgbd
