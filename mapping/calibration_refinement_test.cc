#include "mapping/calibration_refinement.h"

#include <gtest/gtest.h>

#include "core/camera/test_cameras.h"
#include "core/util/error.h"

namespace pkslam {
namespace {

// A problem of `n` keyframes whose observations cover the whole image, with the given angular
// velocities (inertial when not empty) and speed.
CalibrationBundleProblem Problem(int n, const std::vector<Eigen::Vector3d>& rates, double speed,
                                 bool stereo) {
  CalibrationBundleProblem p;
  p.initial.cameras = {testing::EurocCam0()};
  if (stereo) p.initial.cameras.push_back(testing::EurocCam1());
  p.prior = p.initial;
  for (int k = 0; k < n; ++k) {
    p.bundle.visual.keyframes.push_back({k, SE3d(), k == 0});
    p.bundle.inertial.push_back(rates.empty() ? 0 : 1);
    p.bundle.velocities.push_back(Eigen::Vector3d(speed, 0, 0));
    p.angular_velocity.push_back(rates.empty() ? Eigen::Vector3d::Zero()
                                               : rates[static_cast<std::size_t>(k) % rates.size()]);
  }
  p.inertial = !rates.empty();
  for (int y = 0; y < 480; y += 20) {
    for (int x = 0; x < 752; x += 20) {
      CalibrationBundleProblem::RawObservation o;
      o.left = Eigen::Vector2d(x, y);
      o.has_right = stereo;
      p.raw.push_back(o);
    }
  }
  return p;
}

TEST(DecideFreedomTest, ATurningStereoInertialFlightFreesAllButTheLeverArm) {
  const auto p = Problem(20, {{0.3, 0.0, 0.1}, {0.0, 0.4, -0.1}, {-0.2, 0.1, 0.5}}, 0.5, true);
  const CalibrationGates g = DecideFreedom(p, Sensor::kStereoInertial, {});
  EXPECT_TRUE(g.free.intrinsics[0] && g.free.intrinsics[1]);
  EXPECT_TRUE(g.free.stereo_extrinsic);
  EXPECT_TRUE(g.free.imu_rotation);
  EXPECT_TRUE(g.free.time_offset);
  EXPECT_FALSE(g.free.imu_translation);
  EXPECT_EQ(g.frozen.count("imu_translation"), 1u);
  EXPECT_GT(g.second_axis_rate, 0.05);
  OnlineCalibrationOptions lever;
  lever.imu_translation = true;
  EXPECT_TRUE(DecideFreedom(p, Sensor::kStereoInertial, lever).free.imu_translation);
  // The gyro's scale factors are estimated with the rotation unless held.
  EXPECT_TRUE(g.free.gyro_scale);
  OnlineCalibrationOptions held;
  held.gyro_scale = false;
  const CalibrationGates h = DecideFreedom(p, Sensor::kStereoInertial, held);
  EXPECT_FALSE(h.free.gyro_scale);
  EXPECT_NE(h.frozen.at("gyro_scale").find("--calibrate-hold-gyro-scale"), std::string::npos);
  // So are the accelerometer's axis errors.
  EXPECT_TRUE(g.free.accel_axes);
  EXPECT_TRUE(h.free.accel_axes);
  OnlineCalibrationOptions held_accel;
  held_accel.accel_axes = false;
  const CalibrationGates ha = DecideFreedom(p, Sensor::kStereoInertial, held_accel);
  EXPECT_FALSE(ha.free.accel_axes);
  EXPECT_TRUE(ha.free.gyro_scale);
  EXPECT_NE(ha.frozen.at("accel_axes").find("--calibrate-hold-accel-axes"), std::string::npos);
  // The accelerometer's scale factors only when asked for.
  EXPECT_FALSE(g.free.accel_scale);
  EXPECT_NE(g.frozen.at("accel_scale").find("--calibrate-accel-scale"), std::string::npos);
  OnlineCalibrationOptions scale;
  scale.accel_scale = true;
  EXPECT_TRUE(DecideFreedom(p, Sensor::kStereoInertial, scale).free.accel_scale);
  held_accel.accel_scale = true;
  EXPECT_FALSE(DecideFreedom(p, Sensor::kStereoInertial, held_accel).free.accel_scale);
}

TEST(DecideFreedomTest, RotationAboutOneAxisLeavesTheCameraImuRotationFrozen) {
  // Yaw only (as a MAV's first seconds): the rotation about the yaw axis is not observable.
  const auto p = Problem(20, {{0.0, 0.0, 0.4}, {0.0, 0.0, -0.3}}, 0.5, true);
  const CalibrationGates g = DecideFreedom(p, Sensor::kStereoInertial, {});
  EXPECT_FALSE(g.free.imu_rotation);
  ASSERT_EQ(g.frozen.count("imu_rotation"), 1u);
  EXPECT_NE(g.frozen.at("imu_rotation").find("one axis"), std::string::npos);
  EXPECT_FALSE(g.free.gyro_scale);  // nor the gyro's scale about the other axes
  EXPECT_EQ(g.frozen.at("gyro_scale"), g.frozen.at("imu_rotation"));
  EXPECT_FALSE(g.free.accel_axes);
  EXPECT_EQ(g.frozen.at("accel_axes"), g.frozen.at("imu_rotation"));
  EXPECT_TRUE(g.free.time_offset);  // the images move
}

TEST(DecideFreedomTest, AStillRigKeepsTheTimeOffset) {
  const auto p = Problem(20, {{0.001, 0.0, 0.0}, {0.0, 0.001, 0.0}}, 0.01, false);
  const CalibrationGates g = DecideFreedom(p, Sensor::kMonocularInertial, {});
  EXPECT_FALSE(g.free.time_offset);
  EXPECT_EQ(g.frozen.count("time_offset"), 1u);
  // A monocular rig holds its intrinsics unless asked to estimate them.
  EXPECT_FALSE(g.free.intrinsics[0]);
  EXPECT_NE(g.frozen.at("intrinsics").find("monocular"), std::string::npos);
  OnlineCalibrationOptions mono;
  mono.monocular_intrinsics = true;
  const CalibrationGates m = DecideFreedom(p, Sensor::kMonocularInertial, mono);
  EXPECT_TRUE(m.free.intrinsics[0]);
  EXPECT_FALSE(m.free.intrinsics[1]);  // no second camera
}

TEST(DecideFreedomTest, AMonocularInertialRigHoldsTheAccelerometerAxesUnlessAsked) {
  const auto p = Problem(20, {{0.3, 0.0, 0.1}, {0.0, 0.4, -0.1}, {-0.2, 0.1, 0.5}}, 0.5, false);
  const CalibrationGates g = DecideFreedom(p, Sensor::kMonocularInertial, {});
  EXPECT_TRUE(g.free.imu_rotation);  // the turning would free them on a stereo rig
  EXPECT_TRUE(g.free.gyro_scale);
  EXPECT_FALSE(g.free.accel_axes);
  EXPECT_NE(g.frozen.at("accel_axes").find("--calibrate-mono-accel-axes"), std::string::npos);
  EXPECT_FALSE(g.free.accel_scale);
  OnlineCalibrationOptions mono;
  mono.monocular_accel_axes = true;
  EXPECT_TRUE(DecideFreedom(p, Sensor::kMonocularInertial, mono).free.accel_axes);
  // The stereo rig's default is unchanged by the monocular option.
  EXPECT_TRUE(DecideFreedom(p, Sensor::kStereoInertial, {}).free.accel_axes);
}

TEST(DecideFreedomTest, SensorsWithoutScaleOrWithDepthFreezeEverything) {
  const auto p = Problem(20, {}, 0.5, false);
  for (Sensor s : {Sensor::kMonocular, Sensor::kRgbd}) {
    const CalibrationGates g = DecideFreedom(p, s, {});
    EXPECT_FALSE(g.free.Any());
    EXPECT_EQ(g.frozen.size(), 8u);
  }
}

TEST(DecideFreedomTest, TooFewKeyframesOrAPoorlyCoveredImage) {
  const CalibrationGates few = DecideFreedom(Problem(5, {}, 0.5, true), Sensor::kStereo, {});
  EXPECT_FALSE(few.free.Any());
  EXPECT_NE(few.frozen.at("intrinsics").find("5 keyframes"), std::string::npos);
  auto corner = Problem(20, {}, 0.5, true);
  for (auto& o : corner.raw) o.left = Eigen::Vector2d(10, 10);  // all in one cell
  const CalibrationGates g = DecideFreedom(corner, Sensor::kStereo, {});
  EXPECT_FALSE(g.free.intrinsics[0]);
  EXPECT_EQ(g.covered_cells, 1);
  EXPECT_TRUE(g.free.stereo_extrinsic);
}

TEST(ImplausibleEstimateTest, RejectsJumpsAndEstimatesFarFromTheFile) {
  auto p = Problem(20, {{0.3, 0.0, 0.1}}, 0.5, true);
  p.free.intrinsics = {true, true};
  p.free.time_offset = true;
  p.inertial = true;
  const auto shifted = [&](const RigCalibration& c, double dfx, double td_ms) {
    RigCalibration e = c;
    const CameraModel& m = c.cameras[0];
    e.cameras[0] = CameraModel::Pinhole(m.width(), m.height(), m.fx() + dfx, m.fy(), m.cx(), m.cy(),
                                        m.distortion());
    e.time_offset_s += td_ms * 1e-3;
    return e;
  };
  const OnlineCalibrationOptions o;  // priors: 2 px focal, 2 ms offset
  const double max_step = o.max_step_prior_sigmas;
  // A gross file error.
  EXPECT_FALSE(ImplausibleEstimate(p, shifted(p.initial, 5.0, 9.0), o, max_step));
  const auto jump = ImplausibleEstimate(p, shifted(p.initial, 34.0, 0.0), o, max_step);
  ASSERT_TRUE(jump.has_value());
  EXPECT_NE(jump->find("cam0.fx would move 34 px from the file (17 prior sigmas"), std::string::npos)
      << *jump;
  // Far from the file in small steps is still far from the file; a big step from a good start
  // is still a jump.
  p.initial = shifted(p.prior, 19.0, 0.0);
  EXPECT_TRUE(ImplausibleEstimate(p, shifted(p.initial, 3.0, 0.0), o, max_step).has_value());
  p.initial = shifted(p.prior, 0.0, -8.0);
  const auto step = ImplausibleEstimate(p, shifted(p.initial, 0.0, 17.0), o, max_step);
  ASSERT_TRUE(step.has_value());
  EXPECT_NE(step->find("in one adjustment"), std::string::npos) << *step;
}

TEST(OnlineCalibrationOptionsTest, ChecksItself) {
  OnlineCalibrationOptions o;
  EXPECT_NO_THROW(o.Check());
  o.growth = 1.0;
  EXPECT_THROW(o.Check(), OptionError);
  o = {};
  o.prior.focal_px = 0;
  EXPECT_THROW(o.Check(), OptionError);
}

}  // namespace
}  // namespace pkslam
