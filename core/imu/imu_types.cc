#include "core/imu/imu_types.h"

#include <cmath>
#include <utility>

#include "core/util/error.h"

namespace pkslam {

Eigen::Matrix<double, 6, 1> ImuBias::Vector() const {
  Eigen::Matrix<double, 6, 1> v;
  v << gyro, accel;
  return v;
}

void ImuNoise::Check() const {
  for (const auto& [name, value] :
       {std::pair{"gyro_noise_density", gyro_noise_density},
        std::pair{"accel_noise_density", accel_noise_density},
        std::pair{"gyro_random_walk", gyro_random_walk},
        std::pair{"accel_random_walk", accel_random_walk}, std::pair{"rate_hz", rate_hz}}) {
    PKSLAM_CHECK_OPTION(std::isfinite(value) && value > 0, name, "{}", value);
  }
}

Eigen::Matrix<double, 6, 6> DiscreteMeasurementCovariance(const ImuNoise& noise) {
  const double g2 = noise.gyro_noise_density * noise.gyro_noise_density * noise.rate_hz;
  const double a2 = noise.accel_noise_density * noise.accel_noise_density * noise.rate_hz;
  Eigen::Matrix<double, 6, 1> d;
  d << g2, g2, g2, a2, a2, a2;
  return d.asDiagonal();
}

Eigen::Matrix<double, 6, 6> BiasRandomWalkCovariance(const ImuNoise& noise, double dt) {
  const double g2 = noise.gyro_random_walk * noise.gyro_random_walk * dt;
  const double a2 = noise.accel_random_walk * noise.accel_random_walk * dt;
  Eigen::Matrix<double, 6, 1> d;
  d << g2, g2, g2, a2, a2, a2;
  return d.asDiagonal();
}

}  // namespace pkslam
