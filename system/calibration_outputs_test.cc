#include "system/calibration_outputs.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/sensor/test_rig_calibration.h"
#include "io/euroc_sensor.h"
#include "system/rig_factory.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

using ::testing::HasSubstr;
using ::testing::SizeIs;

CalibrationReport Report() {
  CalibrationReport r;
  r.online = true;
  r.covariance_ok = true;
  r.sensor = Sensor::kStereoInertial;
  r.file = testing::EurocRigCalibration();
  r.estimate = r.file;
  r.estimate.time_offset_s = 3.0e-3;
  r.estimate.gyro_scale = Eigen::Vector3d(0.001, 0.0048, -0.0011);
  r.estimate.accel_axes << 0.002, 1.5e-3, -0.7e-3,  //
      -0.4e-3, -0.0013, 2.6e-3,                     //
      0.9e-3, -1.1e-3, 0.0007;
  // cx 0.4 px off at sigma 0.2 (but at least 2/3 px, a third of the prior: no warning), the time
  // offset 3 ms at 0.15 (sigma 2/3 ms: 4.5 sigma), fx 12 px at 0.3 (a gross error: 6 prior
  // sigmas), cy 1.2 px at 0.1 (warned at the floor only: 1.8 sigma, none).
  r.parameters = {{"cam0.cx", "px", 367.215, 367.615, 0.2, 2.0, true},
                  {"cam0.cy", "px", 248.0, 249.2, 0.1, 2.0, true},
                  {"time_offset", "ms", 0.0, 3.0, 0.15, 2.0, true},
                  {"cam1.fx", "px", 469.587, 457.587, 0.3, 2.0, true},
                  {"cam1.fy", "px", 456.134, 456.134, 0.0, 2.0, false},
                  // The gyro's y scale 0.48% at 0.05 (sigma a third of 0.5%: 2.9 sigma, none);
                  // z 2.5% (a file written for another gyro: 15 sigma).
                  {"gyro.sy", "%", 0.0, 0.48, 0.05, 0.5, true},
                  {"gyro.sz", "%", 0.0, 2.5, 0.05, 0.5, true},
                  // The accelerometer's x-y misalignment 1.5 deg at 0.05 (prior 0.2: 22 sigma).
                  {"accel.mxy", "deg", 0.0, 1.5, 0.05, 0.2, true}};
  return r;
}

// The stereo parameters alone: cam0's and cam1's cx moved by the given shifts (estimate - file),
// each with a 0.5 px sigma, correlated so that their difference, the disparity bias (the stereo
// rotation held), has the sigma `bias_sigma` (px).
CalibrationReport StereoBiasReport(double cx0_shift, double cx1_shift, double bias_sigma = 0.05) {
  CalibrationReport r;
  r.online = true;
  r.covariance_ok = true;
  r.sensor = Sensor::kStereo;
  r.file = testing::EurocRigCalibration();
  r.estimate = r.file;
  r.parameters = {{"cam0.fx", "px", 458.654, 458.654, 0.3, 2.0, true},
                  {"cam0.cx", "px", 367.215, 367.215 + cx0_shift, 0.5, 2.0, true},
                  {"cam1.cx", "px", 379.999, 379.999 + cx1_shift, 0.5, 2.0, true},
                  {"stereo.ry", "deg", 0.0, 0.0, 0.0, 0.1, false}};
  const double rho = 1.0 - bias_sigma * bias_sigma / (2 * 0.25);
  r.parameter_covariance = Eigen::MatrixXd::Zero(4, 4);
  r.parameter_covariance(0, 0) = 0.09;
  r.parameter_covariance.block<2, 2>(1, 1) << 0.25, rho * 0.25, rho * 0.25, 0.25;
  return r;
}

TEST(CalibrationWarnings, NameTheStereoDisparityBiasNoParameterShowsAlone) {
  // cam0's cx +0.15 px and cam1's -0.15 px: each within its own sigma, so no parameter's line,
  // but the file's disparities are 0.3 px larger than the estimate's, 6 of the bias's sigmas.
  const CalibrationReport r = StereoBiasReport(0.15, -0.15);
  const auto w = CalibrationWarnings(r, SourcesFromEurocDataset("seq"));
  ASSERT_THAT(w, SizeIs(1));
  EXPECT_THAT(w[0], HasSubstr("the stereo calibration in seq/mav0/cam0/sensor.yaml and "
                              "seq/mav0/cam1/sensor.yaml makes disparities 0.300 px larger"));
  EXPECT_THAT(w[0], HasSubstr("(cam0.cx - cam1.cx + fx stereo.ry; 6.0 sigma)"));
  // 0.3 px of a 458.654 px x 110.1 mm disparity is 1.78% of the depth at 3 m, 4.75% at 8 m.
  const double b = r.estimate.cam1_from_cam0.translation().norm();
  EXPECT_THAT(w[0],
              HasSubstr(fmt::format("stereo depths {:.2f}% too short at 3 m, {:.2f}% at 8 m",
                                    0.3 * 3 / (458.654 * b) * 100, 0.3 * 8 / (458.654 * b) * 100)));
  // Both moved alike leave the disparities as they were: nothing to say.
  EXPECT_TRUE(
      CalibrationWarnings(StereoBiasReport(0.3, 0.3), SourcesFromEurocDataset("seq")).empty());
  // The other way round: disparities smaller, depths long.
  const auto lw =
      CalibrationWarnings(StereoBiasReport(-0.15, 0.15), SourcesFromEurocDataset("seq"));
  ASSERT_THAT(lw, SizeIs(1));
  EXPECT_THAT(lw[0], HasSubstr("0.300 px smaller"));
  EXPECT_THAT(lw[0], HasSubstr("too long at 3 m"));
  // A settings file holds both cameras: named once.
  EXPECT_THAT(CalibrationWarnings(r, SourcesFromSettingsFile("s.yaml"))[0],
              HasSubstr("the stereo calibration in s.yaml makes"));
}

TEST(CalibrationWarnings, TheDisparityBiasSigmaIsAtLeastFourHundredthsOfAPixel) {
  // 0.1 px against a 0.03 px posterior sigma would be 3.3 sigma; at the 0.04 px floor it is 2.5.
  EXPECT_TRUE(
      CalibrationWarnings(StereoBiasReport(0.05, -0.05, 0.03), SourcesFromEurocDataset("seq"))
          .empty());
  const auto fw =
      CalibrationWarnings(StereoBiasReport(0.08, -0.08, 0.03), SourcesFromEurocDataset("seq"));
  ASSERT_THAT(fw, SizeIs(1));
  EXPECT_THAT(fw[0], HasSubstr("(cam0.cx - cam1.cx + fx stereo.ry; 4.0 sigma, 0.04 px)"));
  // Without the covariance the floor is the sigma: 0.3 px is 7.5 of it.
  CalibrationReport r = StereoBiasReport(0.15, -0.15);
  r.covariance_ok = false;
  const auto w = CalibrationWarnings(r, SourcesFromEurocDataset("seq"));
  ASSERT_THAT(w, SizeIs(1));
  EXPECT_THAT(w[0], HasSubstr("7.5 sigma, 0.04 px: no covariance"));
  // Monocular-inertial reports have no cam1.cx: no line.
  CalibrationReport mono = r;
  mono.parameters.erase(mono.parameters.begin() + 2);
  EXPECT_TRUE(CalibrationWarnings(mono, SourcesFromEurocDataset("seq")).empty());
}

TEST(CalibrationWarnings, NameTheParameterTheSizeAndTheFile) {
  const CalibrationReport r = Report();
  const auto w = CalibrationWarnings(r, SourcesFromEurocDataset("seq"));
  ASSERT_THAT(w, SizeIs(4));
  EXPECT_THAT(w[0], HasSubstr("time_offset in seq/mav0/cam0/sensor.yaml (timeshift_cam_imu"));
  EXPECT_THAT(w[0], HasSubstr("-3 ms off the estimate (4.5 sigma, a third of the prior's;"));
  EXPECT_THAT(w[0], ::testing::Not(HasSubstr("wrong for this rig")));
  EXPECT_THAT(w[1], HasSubstr("cam1.fx in seq/mav0/cam1/sensor.yaml is 12 px off"));
  EXPECT_THAT(w[1], HasSubstr("6 times a calibration file's usual error"));
  EXPECT_THAT(w[2], HasSubstr("gyro.sz in seq/mav0/imu0/sensor.yaml (gyroscope_scale_error, "
                              "accelerometer_axis_errors; absent: 0) is -2.5 % off"));
  EXPECT_THAT(w[3], HasSubstr("accel.mxy in seq/mav0/imu0/sensor.yaml (gyroscope_scale_error, "
                              "accelerometer_axis_errors; absent: 0) is -1.5 deg off"));
  // A settings file names itself; without the covariance the prior's third still finds gross
  // errors; with --calibrate off nothing is claimed.
  const auto sw = CalibrationWarnings(r, SourcesFromSettingsFile("s.yaml"));
  ASSERT_THAT(sw, SizeIs(4));
  EXPECT_THAT(sw[0], HasSubstr("in s.yaml"));
  EXPECT_THAT(sw[3],
              HasSubstr("accel.mxy in s.yaml (IMU.GyroScaleX/Y/Z, IMU.AccelAxes; absent: 0)"));
  CalibrationReport no_sigma = r;
  no_sigma.covariance_ok = false;
  const auto nw = CalibrationWarnings(no_sigma, SourcesFromEurocDataset("seq"));
  ASSERT_THAT(nw, SizeIs(4));
  EXPECT_THAT(nw[0], HasSubstr("a third of the prior's: no covariance"));
  CalibrationReport off = r;
  off.online = false;
  EXPECT_TRUE(CalibrationWarnings(off, SourcesFromEurocDataset("seq")).empty());
}

TEST(CalibrationFiles, ReadBackAsEurocSensorsAndSettings) {
  const CalibrationReport r = Report();
  const auto dir = testing::MakeTempDir("calibration_files");
  Settings settings;
  settings.camera1 = r.file.cameras[0];
  settings.camera2 = r.file.cameras[1];
  settings.right_from_left = r.file.cam1_from_cam0;
  settings.body_from_cam0 = r.file.body_from_cam0;
  settings.imu = ImuNoise{};
  settings.fps = 20;
  WriteCalibrationFiles(r, settings, dir);
  const EurocCameraSensor cam0 = ReadEurocCameraSensor(dir / "calibration/cam0/sensor.yaml");
  const EurocCameraSensor cam1 = ReadEurocCameraSensor(dir / "calibration/cam1/sensor.yaml");
  EXPECT_DOUBLE_EQ(cam0.timeshift_cam_imu, 3.0e-3);
  EXPECT_DOUBLE_EQ(cam1.timeshift_cam_imu, 0.0);
  EXPECT_LT((cam1.body_from_camera.Inverse() * r.estimate.body_from_cam1()).Log().norm(), 1e-12);
  EXPECT_EQ(cam0.intrinsics[0], r.estimate.cameras[0].fx());
  const Settings back = ReadOrbSlam3Settings(dir / "calibration/settings.yaml");
  EXPECT_DOUBLE_EQ(back.time_offset_s, 3.0e-3);
  EXPECT_EQ(back.gyro_scale, r.estimate.gyro_scale);
  EXPECT_EQ(back.accel_axes, r.estimate.accel_axes);
  // The IMU's file carries the gyro's scale error and the accelerometer's axis errors in
  // pkslam's keys; EuRoC's keys read as before.
  const EurocImuSensor imu = ReadEurocImuSensor(dir / "calibration/imu0/sensor.yaml");
  EXPECT_EQ(imu.gyroscope_scale_error, r.estimate.gyro_scale);
  EXPECT_EQ(imu.accelerometer_axis_errors, r.estimate.accel_axes);
  EXPECT_EQ(imu.gyroscope_noise_density, ImuNoise{}.gyro_noise_density);
  EXPECT_EQ(imu.rate_hz, ImuNoise{}.rate_hz);
  EXPECT_LT((*back.right_from_left * r.estimate.cam1_from_cam0.Inverse()).Log().norm(), 1e-12);
  // The settings give the rig's calibration its IMU errors back; without an IMU there are none.
  const RigCalibration again = CalibrationFromSettings(back, Sensor::kStereoInertial);
  EXPECT_EQ(again.gyro_scale, r.estimate.gyro_scale);
  EXPECT_EQ(again.accel_axes, r.estimate.accel_axes);
  Settings no_imu = settings;
  no_imu.imu.reset();
  no_imu.body_from_cam0.reset();
  EXPECT_TRUE(SettingsWithCalibration(no_imu, r.estimate).accel_axes.isZero());
  EXPECT_TRUE(SettingsWithCalibration(no_imu, r.estimate).gyro_scale.isZero());
}

}  // namespace
}  // namespace pkslam
