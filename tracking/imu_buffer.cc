#include "tracking/imu_buffer.h"

#include <algorithm>

#include "core/util/error.h"

namespace pkslam {

void ImuBuffer::Add(const std::vector<ImuMeasurement>& samples) {
  for (const ImuMeasurement& m : samples) {
    if (!samples_.empty() && m.t_ns <= samples_.back().t_ns) {
      throw Error(fmt::format("IMU sample at {} ns is not after the previous one ({} ns)", m.t_ns,
                              samples_.back().t_ns));
    }
    samples_.push_back(m);
  }
}

std::optional<PreintegratedImu> ImuBuffer::Between(std::int64_t t0_ns, std::int64_t t1_ns,
                                                   const ImuBias& bias) const {
  const auto& q = samples_;
  if (q.empty() || t1_ns <= t0_ns || q.front().t_ns > t0_ns || q.back().t_ns < t1_ns) {
    return std::nullopt;
  }
  // The last sample at or before t0 through the first at or after t1.
  auto first = std::upper_bound(q.begin(), q.end(), t0_ns,
                                [](std::int64_t t, const ImuMeasurement& m) { return t < m.t_ns; });
  if (first != q.begin()) --first;
  auto last = std::lower_bound(q.begin(), q.end(), t1_ns,
                               [](const ImuMeasurement& m, std::int64_t t) { return m.t_ns < t; });
  std::vector<ImuMeasurement> samples(first, last + 1);
  if (!gyro_scale_.isZero()) {
    const Eigen::Vector3d inverse =
        Eigen::Vector3d::Ones().cwiseQuotient(Eigen::Vector3d::Ones() + gyro_scale_);
    for (ImuMeasurement& m : samples) m.gyro = m.gyro.cwiseProduct(inverse);
  }
  if (accel_correction_) {
    for (ImuMeasurement& m : samples) m.accel = *accel_correction_ * m.accel;
  }
  PreintegratedImu pim = StartPreintegration(bias, noise_);
  IntegrateSamples(samples, t0_ns, t1_ns, &pim);
  return pim;
}

void ImuBuffer::SetAxisErrors(const Eigen::Vector3d& gyro_scale,
                              const Eigen::Matrix3d& accel_axes) {
  gyro_scale_ = gyro_scale;
  accel_correction_.reset();
  if (!accel_axes.isZero(0.0)) {
    accel_correction_ = (Eigen::Matrix3d::Identity() + accel_axes).inverse();
  }
}

void ImuBuffer::KeepFrom(std::int64_t anchor_ns) {
  while (samples_.size() >= 2 && samples_[1].t_ns <= anchor_ns) samples_.pop_front();
}

}  // namespace pkslam
