#include "sim/depth_sensor.h"

#include <algorithm>
#include <cmath>

#include "core/util/error.h"

namespace pkslam::sim {

double KinectDepthModel::EffectiveNoiseK(double noise_scale) const {
  const double gaussian = noise_scale * noise_k;
  const double step = 1.0 / (disparity_steps * disparity_fb);
  return std::sqrt(gaussian * gaussian + step * step / 12.0);
}

cv::Mat KinectDepthImage(const cv::Mat& depth_m, const KinectDepthModel& model, double noise_scale,
                         const PixelNoise& noise, std::uint64_t key, double factor) {
  PKSLAM_CHECK(depth_m.type() == CV_32F, "rendered depth type {} (want CV_32F)", depth_m.type());
  cv::Mat out(depth_m.size(), CV_16U);
  const double steps_fb = model.disparity_steps * model.disparity_fb;
  for (int y = 0; y < depth_m.rows; ++y) {
    for (int x = 0; x < depth_m.cols; ++x) {
      const double z = depth_m.at<float>(y, x);
      if (!(z >= model.min_m && z <= model.max_m)) {
        out.at<std::uint16_t>(y, x) = 0;
        continue;
      }
      double zn = z;
      if (noise_scale > 0.0) {
        const double sigma = noise_scale * model.noise_k * z * z;
        zn = z + sigma * noise.Sample(key, static_cast<std::uint64_t>(y) * depth_m.cols + x);
        // The sensor reports whole 1/steps-pixel disparities: d = fb / z.
        const double levels = std::max(std::round(steps_fb / std::max(zn, 1e-3)), 1.0);
        zn = steps_fb / levels;
      }
      out.at<std::uint16_t>(y, x) =
          static_cast<std::uint16_t>(std::clamp(std::lround(zn * factor), 0L, 65535L));
    }
  }
  return out;
}

}  // namespace pkslam::sim
