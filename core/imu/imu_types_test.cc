#include "core/imu/imu_types.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/util/error.h"

namespace pkslam {
namespace {

TEST(ImuNoise, CheckRejectsNonPositiveOrNonFinite) {
  ImuNoise ok;
  EXPECT_NO_THROW(ok.Check());
  for (double ImuNoise::*field :
       {&ImuNoise::gyro_noise_density, &ImuNoise::accel_noise_density, &ImuNoise::gyro_random_walk,
        &ImuNoise::accel_random_walk, &ImuNoise::rate_hz}) {
    for (const double bad : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(),
                             std::numeric_limits<double>::infinity()}) {
      ImuNoise n;
      n.*field = bad;
      EXPECT_THROW(n.Check(), OptionError) << bad;
    }
  }
}

TEST(ImuNoise, DiscreteCovariances) {
  const ImuNoise n{1e-3, 2e-2, 3e-4, 4e-3, 400.0};
  const Eigen::Matrix<double, 6, 6> meas = DiscreteMeasurementCovariance(n);
  // sigma_d = sigma_c * sqrt(rate).
  EXPECT_DOUBLE_EQ(meas(0, 0), 1e-6 * 400.0);
  EXPECT_DOUBLE_EQ(meas(2, 2), 1e-6 * 400.0);
  EXPECT_DOUBLE_EQ(meas(3, 3), 4e-4 * 400.0);
  EXPECT_DOUBLE_EQ(meas(5, 5), 4e-4 * 400.0);
  EXPECT_EQ(meas(0, 1), 0.0);
  // sigma_d = sigma_c * sqrt(dt).
  const Eigen::Matrix<double, 6, 6> walk = BiasRandomWalkCovariance(n, 0.25);
  EXPECT_DOUBLE_EQ(walk(1, 1), 9e-8 * 0.25);
  EXPECT_DOUBLE_EQ(walk(4, 4), 1.6e-5 * 0.25);
  EXPECT_EQ(walk(3, 4), 0.0);
}

TEST(ImuBias, ArithmeticAndVector) {
  const ImuBias a(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(4, 5, 6));
  const ImuBias b(Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(1, 1, 1));
  const ImuBias d = a - b;
  EXPECT_EQ(d.gyro, Eigen::Vector3d(0.5, 1.5, 2.5));
  EXPECT_EQ(d.accel, Eigen::Vector3d(3, 4, 5));
  EXPECT_EQ(d + b, a);
  EXPECT_FALSE(a == b);
  Eigen::Matrix<double, 6, 1> v;
  v << 1, 2, 3, 4, 5, 6;
  EXPECT_EQ(a.Vector(), v);
}

TEST(PreintegratedImu, StartsEmpty) {
  const PreintegratedImu p;
  EXPECT_EQ(p.dt, 0.0);
  EXPECT_TRUE(p.delta_R.Matrix().isIdentity());
  EXPECT_TRUE(p.covariance.isZero());
  EXPECT_TRUE(p.steps.empty());
}

}  // namespace
}  // namespace pkslam
