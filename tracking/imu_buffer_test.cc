// The tracker's IMU buffer (tracking/imu_buffer.h) on constant-rate synthetic samples.
#include "tracking/imu_buffer.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "core/util/error.h"

namespace pkslam {
namespace {

constexpr std::int64_t kStepNs = 5'000'000;  // 200 Hz

// Samples every 5 ms from t = 0 to `last_ns`, all reading the same rate and specific force.
std::vector<ImuMeasurement> ConstantSamples(std::int64_t last_ns, const Eigen::Vector3d& gyro,
                                            const Eigen::Vector3d& accel) {
  std::vector<ImuMeasurement> samples;
  for (std::int64_t t = 0; t <= last_ns; t += kStepNs) samples.push_back({t, gyro, accel});
  return samples;
}

TEST(ImuBufferTest, IntegratesAConstantRateOverAFrameInterval) {
  ImuBuffer buffer{ImuNoise{}};
  const Eigen::Vector3d gyro(0.0, 0.0, 0.5);
  const Eigen::Vector3d accel(0.2, 0.0, 9.81);
  buffer.Add(ConstantSamples(200'000'000, gyro, accel));
  // An interval that starts and ends between samples: both ends are interpolated.
  const auto pim = buffer.Between(12'000'000, 62'000'000, ImuBias{});
  ASSERT_TRUE(pim.has_value());
  EXPECT_NEAR(pim->dt, 0.05, 1e-12);
  EXPECT_NEAR(pim->delta_R.Log().z(), 0.5 * 0.05, 1e-9);
  EXPECT_NEAR(pim->delta_R.Log().head<2>().norm(), 0.0, 1e-12);
  EXPECT_NEAR(pim->average_gyro.z(), 0.5, 1e-9);
  EXPECT_NEAR(pim->average_accel.z(), 9.81, 1e-9);
}

TEST(ImuBufferTest, RefusesIntervalsTheSamplesDoNotCover) {
  ImuBuffer buffer{ImuNoise{}};
  EXPECT_FALSE(buffer.Between(0, kStepNs, ImuBias{}).has_value()) << "empty buffer";
  buffer.Add(ConstantSamples(100'000'000, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 9.81)));
  EXPECT_FALSE(buffer.Between(50'000'000, 150'000'000, ImuBias{}).has_value()) << "past the end";
  EXPECT_FALSE(buffer.Between(-1, 50'000'000, ImuBias{}).has_value()) << "before the start";
  EXPECT_FALSE(buffer.Between(50'000'000, 50'000'000, ImuBias{}).has_value()) << "empty";
  EXPECT_TRUE(buffer.Between(0, 100'000'000, ImuBias{}).has_value()) << "exactly covered";
}

TEST(ImuBufferTest, GyroScaleDividesTheRates) {
  const Eigen::Vector3d gyro(0.4, -0.2, 1.0);
  ImuBuffer plain{ImuNoise{}};
  ImuBuffer scaled{ImuNoise{}};
  plain.Add(ConstantSamples(100'000'000, gyro, Eigen::Vector3d(0, 0, 9.81)));
  scaled.Add(ConstantSamples(100'000'000, gyro, Eigen::Vector3d(0, 0, 9.81)));
  const Eigen::Vector3d k(0.01, -0.02, 0.03);
  scaled.SetAxisErrors(k, Eigen::Matrix3d::Zero());
  const auto a = plain.Between(0, 100'000'000, ImuBias{});
  const auto b = scaled.Between(0, 100'000'000, ImuBias{});
  ASSERT_TRUE(a && b);
  const Eigen::Vector3d expected = gyro.cwiseQuotient(Eigen::Vector3d::Ones() + k);
  EXPECT_TRUE(b->average_gyro.isApprox(expected, 1e-12)) << b->average_gyro.transpose();
  EXPECT_FALSE(a->average_gyro.isApprox(b->average_gyro, 1e-6));
}

TEST(ImuBufferTest, AccelAxesCorrectTheSpecificForce) {
  // An accelerometer reading (I + E) times the truth: corrected, the buffer integrates the truth.
  const Eigen::Vector3d truth(0.3, -0.5, 9.81);
  Eigen::Matrix3d e;
  e << 0.004, 0.001, -0.002, 0.0015, -0.003, 0.001, -0.001, 0.002, 0.002;
  ImuBuffer plain{ImuNoise{}};
  ImuBuffer corrected{ImuNoise{}};
  const Eigen::Vector3d measured = (Eigen::Matrix3d::Identity() + e) * truth;
  plain.Add(ConstantSamples(100'000'000, Eigen::Vector3d::Zero(), measured));
  corrected.Add(ConstantSamples(100'000'000, Eigen::Vector3d::Zero(), measured));
  corrected.SetAxisErrors(Eigen::Vector3d::Zero(), e);
  const auto a = plain.Between(0, 100'000'000, ImuBias{});
  const auto b = corrected.Between(0, 100'000'000, ImuBias{});
  ASSERT_TRUE(a && b);
  EXPECT_TRUE(b->average_accel.isApprox(truth, 1e-12)) << b->average_accel.transpose();
  EXPECT_TRUE(a->average_accel.isApprox(measured, 1e-12));
  // Back to zero: the samples as given again.
  corrected.SetAxisErrors(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero());
  EXPECT_EQ(corrected.Between(0, 100'000'000, ImuBias{})->delta_v, a->delta_v);
}

TEST(ImuBufferTest, KeepFromKeepsTheSampleBeforeTheAnchorAndRefusesOutOfOrderSamples) {
  ImuBuffer buffer{ImuNoise{}};
  buffer.Add(ConstantSamples(100'000'000, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 9.81)));
  ASSERT_EQ(buffer.size(), 21u);
  buffer.KeepFrom(52'000'000);  // between the samples at 50 and 55 ms
  EXPECT_EQ(buffer.size(), 11u) << "from 50 ms on";
  EXPECT_TRUE(buffer.Between(52'000'000, 100'000'000, ImuBias{}).has_value());
  EXPECT_FALSE(buffer.Between(49'000'000, 100'000'000, ImuBias{}).has_value());
  buffer.KeepFrom(1'000'000'000);
  EXPECT_EQ(buffer.size(), 1u) << "the last sample always stays";
  EXPECT_THROW(buffer.Add({{100'000'000, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}}),
               Error);
  EXPECT_EQ(buffer.size(), 1u);
}

}  // namespace
}  // namespace pkslam
