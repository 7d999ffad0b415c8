#include "core/sensor/rig_calibration.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/camera/test_cameras.h"
#include "core/sensor/test_rig_calibration.h"
#include "core/util/error.h"

namespace pkslam {
namespace {

RigCalibration EurocStereo() { return testing::EurocRigCalibration(); }

RigShape Shape(Sensor sensor) {
  RigShape shape;
  shape.sensor = sensor;
  shape.pyramid = ScalePyramid(8, 1.2);
  return shape;
}

TEST(RigCalibrationTest, StereoRigIsTheRectifiedLeftCamera) {
  const RigCalibration c = EurocStereo();
  const RigSetup setup = BuildRig(c, Shape(Sensor::kStereo));
  ASSERT_TRUE(setup.rectification.has_value());
  EXPECT_NEAR(setup.rig->baseline, c.cam1_from_cam0.translation().norm(), 1e-9);
  EXPECT_DOUBLE_EQ(setup.rig->bf, setup.rig->fx * setup.rig->baseline);
  EXPECT_DOUBLE_EQ(setup.rig->th_depth, 60.0 * setup.rig->baseline);
  EXPECT_FALSE(setup.rig->camera.HasDistortion());
  // body_from_camera is the rectified left camera's pose: its optical centre is cam0's.
  EXPECT_LT((setup.rig->body_from_camera.translation() - c.body_from_cam0.translation()).norm(),
            1e-12);
  EXPECT_GT((setup.rig->body_from_camera.so3().Inverse() * c.body_from_cam0.so3()).Log().norm(),
            1e-4);
}

TEST(RigCalibrationTest, RectifiedInputNeedsNoRectificationUntilTheCalibrationMoves) {
  RigCalibration c;
  const CameraModel pinhole = CameraModel::Pinhole(752, 480, 435.2, 435.2, 367.2, 252.2);
  c.cameras = {pinhole, pinhole};
  c.cam1_from_cam0 = SE3d(SO3d(), Eigen::Vector3d(-0.11, 0, 0));
  RigShape shape = Shape(Sensor::kStereo);
  shape.rectified_input = true;
  const RigSetup ideal = BuildRig(c, shape);
  EXPECT_FALSE(ideal.rectification.has_value());
  EXPECT_DOUBLE_EQ(ideal.rig->baseline, 0.11);
  // An estimate that moved one camera is no longer the ideal pair: it is rectified.
  c.cameras[1] = CameraModel::Pinhole(752, 480, 435.2, 435.2, 367.4, 252.2);
  const RigSetup moved = BuildRig(c, shape);
  EXPECT_TRUE(moved.rectification.has_value());
}

TEST(RigCalibrationTest, WarpBetweenSetupsGoesThroughThePhysicalPixel) {
  const RigCalibration file = EurocStereo();
  RigCalibration estimate = file;
  estimate.cameras[1] = CameraModel::Pinhole(752, 480, 457.587, 456.134, 380.2, 255.3,
                                             testing::EurocCam1().distortion());
  estimate.cam1_from_cam0 = file.cam1_from_cam0 * SE3d::Exp((Eigen::Matrix<double, 6, 1>() << 1e-4,
                                                             0, 0, 0, 2e-4, 0).finished());
  const RigSetup from = BuildRig(file, Shape(Sensor::kStereo));
  const RigSetup to = BuildRig(estimate, Shape(Sensor::kStereo));
  const RigWarp warp(from, to);
  const RigWarp back(to, from);
  // A point seen by both physical cameras: its rectified pixels in either setup are the warp of
  // each other.
  const Eigen::Vector3d p_cam0(0.4, -0.2, 3.0);
  const auto raw_left = file.cameras[0].Project(p_cam0);
  const auto raw_right = estimate.cameras[1].Project(estimate.cam1_from_cam0 * p_cam0);
  ASSERT_TRUE(raw_left && raw_right);
  const auto left_from = TrackingLeftPixel(from, *raw_left);
  const auto left_to = TrackingLeftPixel(to, *raw_left);
  const auto right_from = TrackingRightPixel(from, *raw_right);
  const auto right_to = TrackingRightPixel(to, *raw_right);
  ASSERT_TRUE(left_from && left_to && right_from && right_to);
  EXPECT_LT((*warp.Left(*left_from) - *left_to).norm(), 1e-6);
  EXPECT_LT((*warp.Right(*right_from) - *right_to).norm(), 1e-6);
  EXPECT_LT((*back.Left(*left_to) - *left_from).norm(), 1e-6);
  // In the estimate's rectification the point lies on one row; in the file's it does not.
  EXPECT_NEAR(left_to->y(), right_to->y(), 1e-6);
  EXPECT_GT(std::abs(left_from->y() - right_from->y()), 1e-3);
}

TEST(RigCalibrationTest, MonocularPixelsAreUndistortedRawKeypoints) {
  RigCalibration c;
  c.cameras = {testing::EurocCam0()};
  const RigSetup setup = BuildRig(c, Shape(Sensor::kMonocular));
  EXPECT_FALSE(setup.rectification.has_value());
  const Eigen::Vector2d raw(100.0, 60.0);
  const auto un = TrackingLeftPixel(setup, raw);
  ASSERT_TRUE(un.has_value());
  EXPECT_LT((*un - setup.rig->camera.UndistortPixel(raw)).norm(), 1e-12);
  const auto back = RawLeftPixel(setup, *un);
  ASSERT_TRUE(back.has_value());
  EXPECT_LT((*back - raw).norm(), 1e-6);
}

// A single fisheye is tracked in its pinhole view: keypoints found there go through their raw
// fisheye pixel, and the calibration adjustment whitens them like rectified ones.
TEST(RigCalibrationTest, MonocularFisheyeIsTrackedInItsPinholeView) {
  RigCalibration c;
  c.cameras = {testing::TumViKb8()};
  const RigSetup setup = BuildRig(c, Shape(Sensor::kMonocularInertial));
  ASSERT_TRUE(setup.undistortion.has_value());
  EXPECT_EQ(setup.rig->camera.type(), CameraType::kPinhole);
  EXPECT_FALSE(setup.rig->camera.HasDistortion());
  const Eigen::Vector3d p_camera(0.3, -0.2, 1.0);
  const auto raw = testing::TumViKb8().Project(p_camera);
  ASSERT_TRUE(raw.has_value());
  const auto tracked = TrackingLeftPixel(setup, *raw);
  ASSERT_TRUE(tracked.has_value());
  // The view keeps the fisheye's frame: the point projects there through the rig's pinhole.
  EXPECT_LT((*tracked - *setup.rig->camera.Project(p_camera)).norm(), 1e-6);
  const auto back = RawLeftPixel(setup, *tracked);
  ASSERT_TRUE(back.has_value());
  EXPECT_LT((*back - *raw).norm(), 1e-6);
  // The raw measurement is the fisheye pixel, whitened by d(pinhole pixel)/d(raw pixel), which
  // off the axis stretches the view (the pinhole's magnification grows with the angle).
  const auto m = MakeRawMeasurement(setup, *tracked, -1.0, 1.0, *tracked);
  ASSERT_TRUE(m.has_value());
  EXPECT_LT((m->left - *raw).norm(), 1e-6);
  EXPECT_GT(m->left_whitening.norm(), std::sqrt(2.0) * 1.01);
  EXPECT_FALSE(m->has_right);
}

TEST(RigCalibrationTest, RejectsAnRgbdFisheye) {
  RigCalibration c;
  c.cameras = {testing::TumViKb8()};
  EXPECT_THROW(BuildRig(c, Shape(Sensor::kRgbd)), OptionError);
}

TEST(RigCalibrationTest, RejectsStereoWithoutASecondCamera) {
  RigCalibration c;
  c.cameras = {testing::EurocCam0()};
  EXPECT_THROW(BuildRig(c, Shape(Sensor::kStereo)), OptionError);
}

}  // namespace
}  // namespace pkslam
