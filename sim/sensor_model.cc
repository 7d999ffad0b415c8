#include "sim/sensor_model.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/util/error.h"
#include "sim/texture.h"  // FloorToInt

namespace pkslam::sim {

void SensorOptions::Check() const {
  PKSLAM_CHECK_OPTION(vignetting >= 0.0 && vignetting <= 1.0, "sensor.vignetting", "{}",
                      vignetting);
  PKSLAM_CHECK_OPTION(blur_sigma_px >= 0.0 && blur_sigma_px <= 20.0, "sensor.blur_sigma_px", "{}",
                      blur_sigma_px);
  PKSLAM_CHECK_OPTION(read_noise_dn >= 0.0 && read_noise_dn <= 50.0, "sensor.read_noise_dn", "{}",
                      read_noise_dn);
  PKSLAM_CHECK_OPTION(shot_noise_gain >= 0.0 && shot_noise_gain <= 5.0, "sensor.shot_noise_gain",
                      "{}", shot_noise_gain);
  PKSLAM_CHECK_OPTION(target_brightness > 0.02 && target_brightness < 0.98,
                      "sensor.target_brightness", "{}", target_brightness);
  PKSLAM_CHECK_OPTION(exposure_adapt > 0.0 && exposure_adapt <= 1.0, "sensor.exposure_adapt", "{}",
                      exposure_adapt);
  PKSLAM_CHECK_OPTION(fixed_gain > 0.0, "sensor.fixed_gain", "{}", fixed_gain);
  PKSLAM_CHECK_OPTION(gain_min > 0.0 && gain_max >= gain_min, "sensor.gain_min/max", "{} {}",
                      gain_min, gain_max);
  PKSLAM_CHECK_OPTION(gain_drift >= 0.0 && gain_drift <= 1.0, "sensor.gain_drift", "{}",
                      gain_drift);
  PKSLAM_CHECK_OPTION(max_exposure_s >= 0.0 && max_exposure_s < 0.05, "sensor.max_exposure_s", "{}",
                      max_exposure_s);
  PKSLAM_CHECK_OPTION(veiling_glare >= 0.0 && veiling_glare < 0.5, "sensor.veiling_glare", "{}",
                      veiling_glare);
  PKSLAM_CHECK_OPTION(exposure_at_unit_gain_s > 0.0 && exposure_at_unit_gain_s < 0.05,
                      "sensor.exposure_at_unit_gain_s", "{}", exposure_at_unit_gain_s);
}

SensorModel::SensorModel(const SensorOptions& options, const CameraRays& rays, std::uint64_t seed)
    : options_(options), seed_(seed), drift_rng_(DeriveSeed(seed, 0x4452494654)) {
  options_.Check();
  vignette_.create(rays.height(), rays.width(), CV_32F);
  for (int y = 0; y < rays.height(); ++y) {
    for (int x = 0; x < rays.width(); ++x) {
      const float c = rays.Ray(x, y).z();
      const float c4 = c * c * c * c;
      // Normalised so the loss at 45 deg off-axis (cos^4 = 0.25) equals `vignetting`.
      const float loss = static_cast<float>(options_.vignetting) * (1.0f - c4) / 0.75f;
      vignette_.at<float>(y, x) = std::max(1.0f - loss, 0.05f);
    }
  }
}

double SensorModel::NextGain(const cv::Mat& radiance, double dt_s) {
  if (options_.gain_drift > 0.0) {
    // Slow log-gain random walk (exposure/gain changes the tracker must tolerate).
    drift_ += options_.gain_drift * std::sqrt(std::max(dt_s, 0.0)) * drift_rng_.Normal();
    drift_ = std::clamp(drift_, -1.0, 1.0);
  }
  if (!options_.auto_exposure) {
    gain_ = options_.fixed_gain * std::exp(drift_);
    return gain_;
  }
  cv::Mat grey = radiance;
  if (radiance.channels() == 3) cv::cvtColor(radiance, grey, cv::COLOR_RGB2GRAY);
  const cv::Mat exposed = grey.mul(vignette_);
  // The gain that brings the metered mean to the target. Clipped metering: the mean of
  // min(gain * radiance, 1) grows monotonically with the gain; a few fixed-point steps
  // from the current gain find it (saturated pixels count as full scale, not as their radiance).
  auto metered = [&](double gain) {
    if (!options_.clip_metering) return gain * cv::mean(exposed)[0];
    cv::Mat level = exposed * gain;
    cv::min(level, 1.0, level);
    return cv::mean(level)[0];
  };
  double ideal = options_.target_brightness / std::max(cv::mean(exposed)[0], 1e-4);
  if (options_.clip_metering) {
    for (int i = 0; i < 8; ++i) {
      ideal *= options_.target_brightness / std::max(metered(ideal), 1e-4);
    }
  }
  if (gain_ <= 0.0) {
    gain_ = ideal;  // first frame: start converged
  } else {
    gain_ *= std::pow(ideal / gain_, options_.exposure_adapt);
  }
  gain_ = std::clamp(gain_, options_.gain_min, options_.gain_max);
  return gain_ * std::exp(drift_);
}

double SensorModel::exposure_s() const {
  if (options_.max_exposure_s <= 0.0 || gain_ <= 0.0) return 0.0;
  return std::min(gain_ * options_.exposure_at_unit_gain_s, options_.max_exposure_s);
}

cv::Mat SensorModel::AddVeilingGlare(const cv::Mat& radiance) const {
  // The halo is smooth, so it is computed at an eighth of the resolution (a 0.25-width Gaussian
  // at full size would cost more than the render).
  cv::Mat small;
  cv::resize(radiance, small, cv::Size(std::max(radiance.cols / 8, 1), std::max(radiance.rows / 8, 1)),
             0, 0, cv::INTER_AREA);
  const double sigma = 0.25 * small.cols;
  cv::GaussianBlur(small, small, cv::Size(0, 0), sigma, sigma, cv::BORDER_REFLECT);
  cv::Mat halo;
  cv::resize(small, halo, radiance.size(), 0, 0, cv::INTER_LINEAR);
  const double k = options_.veiling_glare;
  cv::Mat out;
  cv::addWeighted(radiance, 1.0 - k, halo, k, 0.0, out);
  return out;
}

cv::Mat SensorModel::Develop(const cv::Mat& radiance, double gain, std::uint64_t noise_key) const {
  PKSLAM_CHECK(radiance.type() == CV_32FC1 || radiance.type() == CV_32FC3,
               "radiance must be float grey or RGB");
  PKSLAM_CHECK(radiance.rows == vignette_.rows && radiance.cols == vignette_.cols,
               "radiance size does not match the camera");
  cv::Mat blurred = radiance;
  if (options_.blur_sigma_px > 0.0) {
    cv::GaussianBlur(radiance, blurred, cv::Size(0, 0), options_.blur_sigma_px,
                     options_.blur_sigma_px, cv::BORDER_REFLECT);
  }
  if (options_.veiling_glare > 0.0) blurred = AddVeilingGlare(blurred);
  const int channels = radiance.channels();
  cv::Mat out(radiance.rows, radiance.cols, channels == 1 ? CV_8UC1 : CV_8UC3);
  const std::uint64_t key = DeriveSeed(seed_, noise_key);
  const float scale = static_cast<float>(255.0 * gain);
  const float read = static_cast<float>(options_.read_noise_dn);
  const float shot = static_cast<float>(options_.shot_noise_gain);
  tbb::parallel_for(
      tbb::blocked_range<int>(0, radiance.rows), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y != r.end(); ++y) {
          const float* in = blurred.ptr<float>(y);
          const float* vig = vignette_.ptr<float>(y);
          std::uint8_t* dst = out.ptr<std::uint8_t>(y);
          for (int x = 0; x < radiance.cols; ++x) {
            for (int c = 0; c < channels; ++c) {
              const int i = x * channels + c;
              const float level = std::max(in[i] * vig[x] * scale, 0.0f);
              const float sigma = std::sqrt(read * read + shot * level);
              const std::uint64_t index =
                  static_cast<std::uint64_t>(y) * radiance.cols * channels + i;
              const float v = level + sigma * noise_.Sample(key, index);
              dst[i] = static_cast<std::uint8_t>(FloorToInt(std::clamp(v, 0.0f, 255.0f) + 0.5f));
            }
          }
        }
      });
  return out;
}

}  // namespace pkslam::sim
