// The per-keypoint parts of ORB: intensity-centroid orientation and the steered 256-bit
// rBRIEF descriptor (OpenCV's sampling and bit layout, so results equal cv::ORB's for the
// same smoothed image, position and angle).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "core/features/descriptor.h"

namespace pkslam {

// Half-widths u_max[v], v = 0..half_patch, of the discrete disc of radius half_patch used for
// the orientation moments; symmetric under x <-> y so the disc is the same after rotation.
std::vector<int> CircularPatchHalfWidths(int half_patch);

// Orientation by the intensity centroid of a disc of radius half_patch (ORB's u_max disc).
class OrientationDisc {
 public:
  explicit OrientationDisc(int half_patch = 15);

  // Angle (degrees, [0, 360), x right / y down) from `center` to the intensity centroid of
  // the disc around it; `center` must be >= half_patch pixels from every border of `image`.
  float Angle(const cv::Mat& image, cv::Point center) const;

 private:
  static constexpr int kChunk = 16;  // pixels per SIMD step
  int half_;
  std::vector<int> u_max_;
  // Row chunks [start, start + 16) relative to the centre, and per (row v, chunk, lane) the
  // weights u and v (0 outside the disc and where an earlier chunk already counted).
  std::vector<int> chunk_start_;
  std::vector<std::int16_t> u_weight_;
  std::vector<std::int16_t> v_weight_;
};

// The smoothing ORB applies before the binary tests: Gaussian 7x7, sigma 2, reflect-101 border.
void SmoothForDescriptor(const cv::Mat& image, cv::Mat* smoothed);

// The standard 256 ORB tests, for a patch of `patch_size` (31 is the published pattern; other
// sizes scale it and round to whole pixels).
class RbriefPattern {
 public:
  explicit RbriefPattern(int patch_size = 31);

  // Largest distance of a test point from the keypoint; rotated samples stay within
  // ceil(MaxRadius()) pixels of it.
  double MaxRadius() const { return max_radius_; }

  // Descriptor at `center` of the smoothed image, tests rotated by `angle_deg`. The centre
  // must be >= ceil(MaxRadius()) pixels from every border.
  Descriptor Compute(const cv::Mat& smoothed, cv::Point center, float angle_deg) const;

 private:
  // 512 points (x in xs_, y in ys_); test i compares point 2i < point 2i+1.
  std::vector<float> xs_;
  std::vector<float> ys_;
  double max_radius_ = 0.0;
};

}  // namespace pkslam
