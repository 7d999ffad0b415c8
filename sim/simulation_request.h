// A render as its user asks for it (`pkslam simulate`'s flags, Python's pkslam.simulate()), and
// the policy that turns it into SimulationOptions: the realism preset resolved, the scene it
// implies, the camera's frame rate and IMU, the preset's appearance under the sensor values the
// user set. One place for it, so the command line and the Python module render the same bytes.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>

#include "sim/realism.h"
#include "sim/simulator.h"

namespace pkslam::sim {

struct SimulationRequest {
  // Fields the user sets directly (output_dir, trajectory, duration_s, start_s, seed, camera,
  // rgbd, texture_mode, sensor values, ...). `scene` empty: chosen by the realism (DefaultScene).
  // output_dir, trajectory and rgbd also fill `realism`'s replay and rgbd.
  SimulationOptions options;
  std::string motion = "medium";    // random motion: easy|medium|difficult
  std::string quality = "default";  // fast|default|high
  RealismRequest realism;
  std::optional<std::pair<double, double>> blackout;     // black images in [T0, T1] s from start
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();   // initial, rad/s
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();  // initial, m/s^2
  bool imu_noise = true;
  bool cloud = true;   // reference clouds (never without images)
  bool images = true;  // false: IMU and ground truth only
  bool auto_exposure = true;
  // Sensor values of `options` the user set explicitly: they stay over the preset's appearance.
  struct Explicit {
    bool read_noise = false;
    bool blur = false;
    bool vignetting = false;
    bool gain_drift = false;
    bool motion_blur = false;  // a fixed exposure (motion_blur_exposure_s) instead of auto's
  } given;
};

// The request's realism with what the options imply filled in (replay, rgbd).
RealismRequest RealismOf(const SimulationRequest& request);

// The options a request renders with. OptionError naming the option for a bad value.
SimulationOptions ResolveSimulation(const SimulationRequest& request);

// Whether a render with these options is a stereo sequence on disk, the one its camera's other
// layouts (TUM-VI files, KITTI's) are written beside.
bool WritesStereoSequence(const SimulationOptions& options);

// Renders the request: RunSimulation on its options, then the other layouts its camera asks for
// (tumvi: TUM-VI's dso/camchain.yaml, imu_config.yaml and mocap0; kitti: KITTI's odometry layout
// under OUT/kitti, images hard-linked). `resolved` (if given) receives the options used.
SimulationSummary Simulate(const SimulationRequest& request, SimulationOptions* resolved = nullptr);

}  // namespace pkslam::sim
