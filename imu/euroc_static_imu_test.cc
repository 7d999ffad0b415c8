// Real IMU data: the static EuRoC slice (V1_01_easy before take-off, rotors running). Reads it
// with io's EuRoC reader (a test-only use of the io library above imu).
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "imu/preintegration.h"
#include "io/euroc_dataset.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

using Vec3 = Eigen::Vector3d;

TEST(EurocStaticImu, GravityMagnitudeAndGyroBiasFromTheStaticSlice) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const EurocDataset d = EurocDataset::Open(shared / "euroc" / "V1_01_easy_static");
  ASSERT_TRUE(d.has_imu());
  // The camera span of the slice (~4.7 s), during which the platform stands still.
  const std::int64_t t0 = d.cam0().images.front().t_ns;
  const std::int64_t t1 = d.cam0().images.back().t_ns;
  const ImuNoise noise{d.imu_sensor().gyroscope_noise_density,
                       d.imu_sensor().accelerometer_noise_density,
                       d.imu_sensor().gyroscope_random_walk,
                       d.imu_sensor().accelerometer_random_walk, d.imu_sensor().rate_hz};
  // The samples from the last one at or before t0 through the first one at or after t1.
  std::vector<ImuSample> samples;
  for (const ImuSample& s : d.imu()) {
    if (s.t_ns >= t0 - 5'000'000 && s.t_ns <= t1 + 5'000'000) samples.push_back(s);
  }
  ASSERT_GT(samples.size(), 900u);

  PreintegratedImu raw = StartPreintegration({}, noise);
  const int steps = IntegrateSamples(samples, t0, t1, &raw);
  // The time-weighted mean angular velocity (bias-uncorrected) is the gyro bias estimate.
  const Vec3 gyro_bias = raw.average_gyro;
  // Re-integrated with that gyro bias removed, the rotation over the slice nearly vanishes,
  // the mean specific force is gravity's, and so is |delta_v| / dT.
  PreintegratedImu corrected = raw;
  Reintegrate(ImuBias(gyro_bias, Vec3::Zero()), &corrected);
  const Vec3 mean_accel = corrected.average_accel;
  const double g_from_dv = corrected.delta_v.norm() / corrected.dt;

  // Plain sample statistics for comparison (rotor vibration dominates the spread).
  Vec3 sum = Vec3::Zero(), sum_sq = Vec3::Zero(), gyro_sum = Vec3::Zero();
  for (const ImuSample& s : samples) {
    sum += s.accel;
    sum_sq += s.accel.cwiseAbs2();
    gyro_sum += s.gyro;
  }
  const double n = static_cast<double>(samples.size());
  const Vec3 sample_mean = sum / n;
  const Vec3 accel_std = ((sum_sq - n * sample_mean.cwiseAbs2()) / (n - 1)).cwiseSqrt();
  const Vec3 gyro_mean = gyro_sum / n;

  std::printf(
      "[ static EuRoC ] %.3f s, %d steps, %zu samples\n"
      "[ static EuRoC ] mean specific force (%.4f, %.4f, %.4f) m/s^2, |.| = %.4f\n"
      "[ static EuRoC ] |delta_v| / dT = %.4f m/s^2; plain sample mean |.| = %.4f m/s^2\n"
      "[ static EuRoC ] gyro bias estimate (%.5f, %.5f, %.5f) rad/s (sample mean %.5f %.5f "
      "%.5f)\n"
      "[ static EuRoC ] rotation over the slice: raw %.4f rad, bias-corrected %.2e rad\n"
      "[ static EuRoC ] accel std (%.3f, %.3f, %.3f) m/s^2\n",
      raw.dt, steps, samples.size(), mean_accel.x(), mean_accel.y(), mean_accel.z(),
      mean_accel.norm(), g_from_dv, sample_mean.norm(), gyro_bias.x(), gyro_bias.y(), gyro_bias.z(),
      gyro_mean.x(), gyro_mean.y(), gyro_mean.z(), raw.delta_R.Angle(), corrected.delta_R.Angle(),
      accel_std.x(), accel_std.y(), accel_std.z());

  EXPECT_NEAR(raw.dt, 1e-9 * static_cast<double>(t1 - t0), 1e-9);
  EXPECT_NEAR(mean_accel.norm(), 9.81, 0.1);
  EXPECT_NEAR(g_from_dv, 9.81, 0.1);
  // A static gyro reads its bias: well above the noise of a 4.7 s mean (~1e-4 rad/s), well
  // below any motion; the bias-corrected rotation over the slice is tiny.
  EXPECT_GT(gyro_bias.norm(), 0.01);
  EXPECT_LT(gyro_bias.norm(), 0.2);
  EXPECT_LT((gyro_bias - gyro_mean).norm(), 1e-3);
  EXPECT_NEAR(mean_accel.norm(), sample_mean.norm(), 0.01);
  EXPECT_LT(corrected.delta_R.Angle(), 0.01);
  EXPECT_GT(raw.delta_R.Angle(), 10 * corrected.delta_R.Angle());
}

}  // namespace
}  // namespace pkslam
