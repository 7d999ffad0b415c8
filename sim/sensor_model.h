// Image formation after the renderer: vignetting, optical blur, exposure/gain (auto exposure
// with lag, or fixed, plus optional slow random drift), Gaussian read noise and shot noise,
// 8-bit quantisation. Deterministic: pixel noise comes from a counter-based hash of
// (seed, frame, camera, pixel), so threads and row order do not change the bytes.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "sim/random.h"
#include "sim/renderer.h"

namespace pkslam::sim {

struct SensorOptions {
  double vignetting = 0.35;         // brightness loss at 45 deg off-axis: 1 - v * (1 - cos^4)
  double blur_sigma_px = 0.5;       // optical blur (Gaussian sigma, pixels; 0 = none)
  double read_noise_dn = 1.0;       // Gaussian read noise (8-bit levels, std)
  double shot_noise_gain = 0.04;    // shot noise variance per level (DN per electron)
  bool auto_exposure = true;        // adapt the gain towards target_brightness
  double target_brightness = 0.42;  // mean image level / 255 the auto exposure aims for
  double exposure_adapt = 0.3;      // fraction of the log-brightness error corrected per frame
  double fixed_gain = 1.6;          // gain when auto exposure is off (radiance 1 -> 255 * gain)
  double gain_min = 0.2;            // auto exposure limits
  double gain_max = 8.0;
  double gain_drift = 0.0;  // relative std of a slow random gain drift per second
  // Auto exposure meters the clipped 8-bit image, as a camera's AEC does: a saturated window
  // does not darken the rest of the frame more than its 255s weigh.
  bool clip_metering = false;
  // > 0: the exposure time follows the auto exposure (gain * exposure_at_unit_gain_s) up to
  // this cap, beyond which analog gain takes over; the simulator blurs over it.
  double max_exposure_s = 0.0;
  double exposure_at_unit_gain_s = 0.002;  // exposure time of gain 1 (radiance 1 -> 255)
  // Veiling glare (lens flare's diffuse part, ISO 9358): this fraction of the light reaching
  // the sensor is scattered over it, in a wide halo (a quarter of the image width) around
  // where it came from, so a bright window lifts and flattens the dark parts of its frame.
  double veiling_glare = 0.0;

  void Check() const;
};

// Threads: NextGain() updates the exposure state and belongs to the one thread driving the
// frame loop; Develop() is const (it parallelises rows internally with TBB).
class SensorModel {
 public:
  // Precomputes the vignetting map of the camera.
  SensorModel(const SensorOptions& options, const CameraRays& rays, std::uint64_t seed);

  // Exposure control: feed the (reference camera's) radiance of each frame in order; returns
  // the gain to develop all cameras of that frame with. dt_s: time since the previous frame.
  double NextGain(const cv::Mat& radiance, double dt_s);
  double gain() const { return gain_; }
  bool initialised() const { return gain_ > 0.0; }
  // Exposure time of the next frame (0 when the exposure model is off or before the first
  // frame): the auto exposure sets it from the previous frames, as a real AEC lags by a frame.
  double exposure_s() const;

  // Radiance (CV_32FC1 or CV_32FC3) -> 8-bit (CV_8UC1 or CV_8UC3, same channel order).
  // noise_key distinguishes frames and cameras (e.g. DeriveSeed(frame, camera)).
  cv::Mat Develop(const cv::Mat& radiance, double gain, std::uint64_t noise_key) const;

 private:
  cv::Mat AddVeilingGlare(const cv::Mat& radiance) const;

  SensorOptions options_;
  cv::Mat vignette_;  // CV_32F
  std::uint64_t seed_;
  double gain_ = 0.0;  // 0: not initialised
  double drift_ = 0.0;
  Rng drift_rng_;
  PixelNoise noise_;
};

}  // namespace pkslam::sim
