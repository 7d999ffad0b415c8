// Deterministic textured test images (tests and benchmarks): smooth shading, random polygons
// and ellipses (corners at all scales) and mild noise.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace pkslam {

inline cv::Mat SyntheticTexture(cv::Size size, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat coarse(size.height / 16 + 2, size.width / 16 + 2, CV_32F);
  rng.fill(coarse, cv::RNG::UNIFORM, 40.0, 215.0);
  cv::Mat image;
  cv::resize(coarse, image, size, 0, 0, cv::INTER_CUBIC);
  const int n_shapes = size.area() / 500;
  for (int i = 0; i < n_shapes; ++i) {
    const cv::Point2f centre(rng.uniform(0.0f, float(size.width)),
                             rng.uniform(0.0f, float(size.height)));
    const float radius = rng.uniform(3.0f, 30.0f);
    const double value = rng.uniform(0.0, 255.0);
    if (rng.uniform(0, 3) == 0) {
      cv::ellipse(image,
                  cv::RotatedRect(centre, {radius * 2, radius * rng.uniform(0.5f, 2.0f)},
                                  rng.uniform(0.0f, 180.0f)),
                  cv::Scalar(value), cv::FILLED, cv::LINE_AA);
    } else {
      const int corners = rng.uniform(3, 6);
      std::vector<cv::Point> polygon;
      const double start = rng.uniform(0.0, CV_2PI);
      for (int k = 0; k < corners; ++k) {
        const double a = start + k * CV_2PI / corners + rng.uniform(-0.4, 0.4);
        const double r = radius * rng.uniform(0.6, 1.0);
        polygon.emplace_back(cvRound(centre.x + r * std::cos(a)),
                             cvRound(centre.y + r * std::sin(a)));
      }
      cv::fillConvexPoly(image, polygon, cv::Scalar(value), cv::LINE_AA);
    }
  }
  cv::Mat noise(size, CV_32F);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 3.0);
  image += noise;
  cv::GaussianBlur(image, image, cv::Size(0, 0), 0.7);
  cv::Mat out;
  image.convertTo(out, CV_8U);
  return out;
}

}  // namespace pkslam
