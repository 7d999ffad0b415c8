// Kinect v1-like depth images from rendered depth (structured light; Khoshelham & Elberink
// 2012): Gaussian random error sigma_z = k z^2 (k = 1.425e-3 1/m), then the sensor's
// disparity quantisation. Kinect v1 measures disparity in 1/8 pixel steps of its IR camera
// (f ~ 580 px, projector baseline ~ 7.5 cm), so depth comes in levels spaced
// z^2 / (8 f b) = 2.87e-3 z^2 apart (7 cm at 5 m). Together: sigma ~ 1.65e-3 z^2 (4 cm at
// 5 m, the paper's random error).
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "sim/random.h"

namespace pkslam::sim {

struct KinectDepthModel {
  double noise_k = 1.425e-3;            // Gaussian sigma_z = noise_k z^2 (m), times the noise scale
  double disparity_fb = 580.0 * 0.075;  // f * b of the IR camera-projector pair (px m)
  double disparity_steps = 8.0;         // disparity resolution: 1 / steps pixels
  double min_m = 0.4;                   // valid range; outside it the pixel is 0 (invalid)
  double max_m = 8.0;

  // Depth level spacing at z: z^2 / (steps * fb).
  double LevelSpacing(double z) const { return z * z / (disparity_steps * disparity_fb); }
  // k of the total sigma (Gaussian plus uniform quantisation error) at noise scale s:
  // sqrt((s k)^2 + (1 / (steps fb))^2 / 12).
  double EffectiveNoiseK(double noise_scale) const;
};

// Metric depth (CV_32F, rendered) -> CV_16U depth image in metres * factor. noise_scale 0
// gives the exact depth (no noise, no quantisation). Deterministic in (noise, key, pixel).
cv::Mat KinectDepthImage(const cv::Mat& depth_m, const KinectDepthModel& model, double noise_scale,
                         const PixelNoise& noise, std::uint64_t key, double factor);

}  // namespace pkslam::sim
