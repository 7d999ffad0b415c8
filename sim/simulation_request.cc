#include "sim/simulation_request.h"

#include <fmt/format.h>

#include "core/util/error.h"
#include "io/kalibr_files.h"
#include "io/kitti_writer.h"
#include "sim/motion_generator.h"

namespace pkslam::sim {
namespace {

// The preset's appearance, then the sensor values the user gave on top of it.
void ApplyAppearanceUnderGiven(const SimulationRequest::Explicit& given,
                               SimulationOptions* options) {
  const SensorOptions user = options->sensor;
  const double user_blur_exposure = options->motion_blur_exposure_s;
  ApplyAppearance(options->realism.appearance, options);
  if (given.read_noise) options->sensor.read_noise_dn = user.read_noise_dn;
  if (given.blur) options->sensor.blur_sigma_px = user.blur_sigma_px;
  if (given.vignetting) options->sensor.vignetting = user.vignetting;
  if (given.gain_drift) options->sensor.gain_drift = user.gain_drift;
  if (given.motion_blur) {
    options->sensor.max_exposure_s = 0.0;
    options->motion_blur_exposure_s = user_blur_exposure;
  }
}

// The camera's own frame rate and, for TUM-VI, its IMU.
void ApplyCamera(SimulationOptions* o) {
  if (o->camera == "kitti") o->camera_rate_hz = 10.0;  // KITTI odometry's frame rate
  if (o->camera == "tumvi") {
    // TUM-VI's Bosch BMI160 as its calibration states it (the values of ORB-SLAM3's TUM-VI
    // settings), cameras at 20 Hz.
    o->camera_rate_hz = 20.0;
    o->imu.gyro_noise_density = 0.00016;
    o->imu.accel_noise_density = 0.0028;
    o->imu.gyro_random_walk = 0.000022;
    o->imu.accel_random_walk = 0.00086;
    o->imu.rate_hz = 200.0;
  }
}

}  // namespace

RealismRequest RealismOf(const SimulationRequest& request) {
  RealismRequest realism = request.realism;
  realism.replay = !request.options.trajectory.empty();
  realism.rgbd = request.options.rgbd;
  return realism;
}

bool WritesStereoSequence(const SimulationOptions& o) {
  return !o.rgbd && o.write_images && !o.bench && !o.reference_only;
}

SimulationOptions ResolveSimulation(const SimulationRequest& request) {
  SimulationOptions o = request.options;
  o.realism = ResolveRealism(RealismOf(request));
  if (o.scene.empty()) o.scene = DefaultScene(o.realism, o.trajectory);
  o.motion.level = ParseMotionLevel(request.motion);
  if (o.trajectory.empty() && o.duration_s > 0 && o.duration_s <= o.motion.rest_s) {
    throw OptionError(
        fmt::format("--duration {}: random motion starts with {} s at rest (as "
                    "EuRoC's flights before take-off); give more than that",
                    o.duration_s, o.motion.rest_s));
  }
  o.quality = ParseQuality(request.quality);
  if (request.blackout) {
    o.blackout_begin_s = request.blackout->first;
    o.blackout_end_s = request.blackout->second;
  }
  o.imu.initial_gyro_bias = request.gyro_bias;
  o.imu.initial_accel_bias = request.accel_bias;
  o.imu.noise = request.imu_noise;
  o.write_cloud = request.cloud && request.images;
  o.write_images = request.images;
  ApplyCamera(&o);
  if (o.realism.On(RealismSource::kAppearance)) ApplyAppearanceUnderGiven(request.given, &o);
  o.sensor.auto_exposure = request.auto_exposure;
  return o;
}

SimulationSummary Simulate(const SimulationRequest& request, SimulationOptions* resolved) {
  const SimulationOptions o = ResolveSimulation(request);
  if (resolved != nullptr) *resolved = o;
  const SimulationSummary summary = RunSimulation(o);
  const bool stereo_sequence = WritesStereoSequence(o);
  if (o.camera == "tumvi" && stereo_sequence) WriteTumViFiles(o.output_dir);
  // The same sequence in KITTI odometry's layout beside the EuRoC one, so `run --dataset
  // OUT/kitti/sequences/00` and `eval --kitti` have exact poses.
  if (o.camera == "kitti" && stereo_sequence) {
    WriteKittiLayoutFromEuroc(o.output_dir, o.output_dir / "kitti", "00");
  }
  return summary;
}

}  // namespace pkslam::sim
