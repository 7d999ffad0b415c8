// The IMU samples tracking was given and still needs, and their preintegration over a frame or
// keyframe interval. Tracking thread only (owned by the Tracker's inertial state).
//
// The buffer keeps a time-ordered deque; KeepFrom trims it to what the oldest anchor (last
// keyframe, last frame, monocular initial frame) still needs, so it stays a few frames long.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "core/imu/imu_types.h"
#include "imu/preintegration.h"

namespace pkslam {

class ImuBuffer {
 public:
  explicit ImuBuffer(const ImuNoise& noise) : noise_(noise) {}

  // Appends samples; each must be later than the one before it (throws Error naming both
  // times otherwise, and keeps the samples before the offending one).
  void Add(const std::vector<ImuMeasurement>& samples);

  // The IMU's axis errors (online calibration, RigCalibration::gyro_scale and accel_axes): rates
  // are divided by 1 + k per axis and specific forces multiplied by (I + E)^-1 as they are
  // integrated. Zero (the default) integrates the samples as given.
  void SetAxisErrors(const Eigen::Vector3d& gyro_scale, const Eigen::Matrix3d& accel_axes);
  // A new IMU noise model (a recalibrated rig).
  void SetNoise(const ImuNoise& noise) { noise_ = noise; }

  // The preintegration over [t0_ns, t1_ns] linearised at `bias` (imu/preintegration.h's
  // IntegrateSamples over the last sample at or before t0 through the first at or after t1);
  // nullopt when the samples do not cover the interval or it is empty.
  std::optional<PreintegratedImu> Between(std::int64_t t0_ns, std::int64_t t1_ns,
                                          const ImuBias& bias) const;

  // Drops every sample before the last one at or before `anchor_ns` (which Between still
  // needs for an interval starting at the anchor).
  void KeepFrom(std::int64_t anchor_ns);

  std::size_t size() const { return samples_.size(); }

 private:
  std::deque<ImuMeasurement> samples_;
  ImuNoise noise_;
  Eigen::Vector3d gyro_scale_ = Eigen::Vector3d::Zero();
  std::optional<Eigen::Matrix3d> accel_correction_;  // (I + E)^-1; unset for E = 0
};

}  // namespace pkslam
