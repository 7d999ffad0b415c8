#include "sim/sensor_model.h"

#include <gtest/gtest.h>

#include "core/camera/camera_model.h"
#include "sim/renderer.h"

namespace pkslam::sim {
namespace {

// A frame whose top tenth is a window 100x brighter than the room.
cv::Mat WindowFrame(const CameraRays& rays) {
  cv::Mat radiance(rays.height(), rays.width(), CV_32F, cv::Scalar(0.3));
  radiance.rowRange(0, rays.height() / 10).setTo(30.0);
  return radiance;
}

SensorOptions Flat() {
  SensorOptions o;
  o.vignetting = 0.0;
  o.target_brightness = 0.57;
  return o;
}

TEST(SensorModel, ClippedMeteringExposesTheRoomNotTheWindow) {
  const CameraRays rays(CameraModel::Pinhole(200, 100, 100, 100, 99.5, 49.5));
  SensorOptions o = Flat();
  SensorModel plain(o, rays, 1);
  const double plain_gain = plain.NextGain(WindowFrame(rays), 0.05);
  o.clip_metering = true;
  SensorModel clipped(o, rays, 1);
  const double clipped_gain = clipped.NextGain(WindowFrame(rays), 0.05);
  // mean(min(g r, 1)) = 0.57 with 10% saturated: 0.9 * 0.3 g + 0.1 = 0.57 -> g = 1.7407.
  EXPECT_NEAR(clipped_gain, 0.47 / 0.27, 1e-3);
  // Metering the raw radiance would drive the room to a fifth of that.
  EXPECT_LT(plain_gain, 0.2 * clipped_gain);
  const cv::Mat image = clipped.Develop(WindowFrame(rays), clipped_gain, 3);
  EXPECT_NEAR(cv::mean(image)[0], 0.57 * 255, 2.0);
}

TEST(SensorModel, ExposureTimeFollowsTheGainUpToItsCap) {
  const CameraRays rays(CameraModel::Pinhole(200, 100, 100, 100, 99.5, 49.5));
  SensorOptions o = Flat();
  SensorModel off(o, rays, 1);
  off.NextGain(WindowFrame(rays), 0.05);
  EXPECT_EQ(off.exposure_s(), 0.0);  // the model is off
  o.max_exposure_s = 0.010;
  o.exposure_at_unit_gain_s = 0.002;
  o.clip_metering = true;
  SensorModel on(o, rays, 1);
  EXPECT_EQ(on.exposure_s(), 0.0);  // no frame metered yet
  const double gain = on.NextGain(WindowFrame(rays), 0.05);
  EXPECT_NEAR(on.exposure_s(), 0.002 * gain, 1e-12);
  SensorModel dark(o, rays, 1);
  dark.NextGain(cv::Mat(rays.height(), rays.width(), CV_32F, cv::Scalar(0.01)), 0.05);
  EXPECT_EQ(dark.exposure_s(), 0.010);  // capped: the rest is analog gain
}

TEST(SensorModel, VeilingGlareLiftsTheRoomUnderAWindow) {
  const CameraRays rays(CameraModel::Pinhole(200, 100, 100, 100, 99.5, 49.5));
  SensorOptions o = Flat();
  o.read_noise_dn = 0.0;
  o.shot_noise_gain = 0.0;
  o.blur_sigma_px = 0.0;
  const SensorModel clean(o, rays, 1);
  o.veiling_glare = 0.1;
  const SensorModel glaring(o, rays, 1);
  const double gain = 0.03;  // nothing saturates: the window at 230 DN, the room at 2.3 DN
  const cv::Mat a = clean.Develop(WindowFrame(rays), gain, 1);
  const cv::Mat b = glaring.Develop(WindowFrame(rays), gain, 1);
  const cv::Rect lower_room(0, 50, 200, 50);
  // A tenth of the light goes into the halo, which the window dominates: the room far below it
  // brightens by several times its own tenth (0.23 DN), the window dims.
  EXPECT_GT(cv::mean(b(lower_room))[0], cv::mean(a(lower_room))[0] + 1.0);
  EXPECT_LT(cv::mean(b.rowRange(0, 5))[0], cv::mean(a.rowRange(0, 5))[0] - 5.0);
  // Light is moved, not made: the frame's mean stays.
  EXPECT_NEAR(cv::mean(b)[0], cv::mean(a)[0], 1.0);
}

}  // namespace
}  // namespace pkslam::sim
