// Per-level scale tables of the ORB pyramid (level 0 = full resolution).
#pragma once

#include <cmath>
#include <vector>

namespace pkslam {

struct ScalePyramid {
  int n_levels = 8;
  double scale_factor = 1.2;
  double log_scale_factor = std::log(1.2);
  std::vector<double> scale;       // scale_factor^level
  std::vector<double> inv_scale;   // 1 / scale
  std::vector<double> sigma2;      // scale^2: keypoint position variance per level
  std::vector<double> inv_sigma2;  // 1 / sigma2

  ScalePyramid() : ScalePyramid(8, 1.2) {}
  ScalePyramid(int levels, double factor)
      : n_levels(levels), scale_factor(factor), log_scale_factor(std::log(factor)) {
    scale.resize(levels);
    inv_scale.resize(levels);
    sigma2.resize(levels);
    inv_sigma2.resize(levels);
    double s = 1.0;
    for (int i = 0; i < levels; ++i) {
      scale[i] = s;
      inv_scale[i] = 1.0 / s;
      sigma2[i] = s * s;
      inv_sigma2[i] = 1.0 / (s * s);
      s *= factor;
    }
  }
};

}  // namespace pkslam
