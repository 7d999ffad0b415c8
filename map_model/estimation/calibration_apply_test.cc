#include "map_model/estimation/calibration_apply.h"

#include <gtest/gtest.h>

#include <mutex>
#include <shared_mutex>

#include "core/camera/test_cameras.h"
#include "core/sensor/test_rig_calibration.h"
#include "imu/preintegration.h"
#include "map_model/estimation/calibration_collect.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

RigShape StereoShape() {
  RigShape shape;
  shape.sensor = Sensor::kStereo;
  shape.pyramid = ScalePyramid(8, 1.2);
  return shape;
}

RigCalibration EurocFile() { return testing::EurocRigCalibration(); }

// A map built in the rectified camera of the EuRoC calibration, the Atlas holding that
// calibration.
class CalibrationApplyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    file_ = EurocFile();
    setup_ = BuildRig(file_, StereoShape());
    {
      auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
      atlas_.SetCalibration(lock, file_, setup_);
    }
    scene_ = testing::MakeScene(500, 7);
    map_ = testing::MakeMap(&atlas_, scene_, setup_.rig, testing::MakeForwardPath(12, 0.15, 8),
                            testing::FrameOptions{});
  }

  // Gives every keyframe after the first the same preintegration (0.2 s of a constant sample,
  // integrated at `bias`) and that bias as its state's: a chain to move. Returns it.
  PreintegratedImu SetChain(const ImuBias& bias) {
    PreintegratedImu pim = StartPreintegration(bias, ImuNoise{});
    for (int i = 0; i < 40; ++i) {
      IntegrateMeasurement(Eigen::Vector3d(0.1, 9.8, 0.2), Eigen::Vector3d(0.3, 0.8, -0.2), 0.005,
                           &pim);
    }
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    for (std::size_t k = 1; k < map_.keyframes.size(); ++k) {
      map_.keyframes[k]->mutable_imu(lock).from_previous = pim;
      map_.keyframes[k]->mutable_imu(lock).state.bias = bias;
    }
    return pim;
  }

  Atlas atlas_;
  RigCalibration file_;
  RigSetup setup_;
  testing::SyntheticScene scene_;
  testing::SyntheticMap map_;
};

TEST_F(CalibrationApplyTest, MovingToAnEstimateKeepsPhysicalPixelsAndBodies) {
  RigCalibration estimate = file_;
  estimate.cameras[1] = CameraModel::Pinhole(752, 480, 457.9, 456.134, 380.3, 255.238,
                                             testing::EurocCam1().distortion());
  estimate.body_from_cam0 =
      SE3d::Exp((Eigen::Matrix<double, 6, 1>() << 0, 0, 0, 2e-3, -1e-3, 3e-3).finished()) *
      file_.body_from_cam0;
  const RigSetup next = BuildRig(estimate, StereoShape());
  const KeyFrame& kf = *map_.keyframes[5];
  std::vector<Eigen::Vector2d> raw_before;
  std::vector<Eigen::Vector2d> raw_right_before;
  for (int i = 0; i < kf.size(); ++i) {
    const cv::Point2f p = kf.keypoints_undistorted()[i].pt;
    raw_before.push_back(*RawLeftPixel(setup_, Eigen::Vector2d(p.x, p.y)));
    raw_right_before.push_back(kf.right_u()[i] >= 0
                                   ? *RawRightPixel(setup_, Eigen::Vector2d(kf.right_u()[i], p.y))
                                   : Eigen::Vector2d::Zero());
  }
  const SE3d body_before = kf.world_from_body();
  const int version = atlas_.calibration_version();
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kCalibration);
    MoveToCalibration(lock, &atlas_, estimate, next);
  }
  auto lock = MapReader(atlas_).Lock();
  EXPECT_EQ(atlas_.calibration_version(), version + 1);
  EXPECT_EQ(atlas_.rig_setup().rig, next.rig);
  EXPECT_EQ(kf.rig_ptr(), next.rig);
  // The body stays where it was; the tracking camera moved with the new extrinsic.
  EXPECT_LT((kf.world_from_body().Inverse() * body_before).Log().norm(), 1e-12);
  int stereo = 0;
  for (int i = 0; i < kf.size(); ++i) {
    const cv::Point2f p = kf.keypoints_undistorted()[i].pt;
    // Every keypoint is still the pixel the physical camera measured (float keypoints).
    EXPECT_LT((*RawLeftPixel(next, Eigen::Vector2d(p.x, p.y)) - raw_before[i]).norm(), 2e-3);
    if (kf.right_u()[i] < 0) continue;
    ++stereo;
    // The right column moved with cam1's new cx (0.3 px), and the depth with the new bf.
    EXPECT_NEAR(kf.depth()[i], next.rig->bf / (p.x - kf.right_u()[i]), 1e-3 * kf.depth()[i]);
    const Eigen::Vector2d raw_right = *RawRightPixel(next, Eigen::Vector2d(kf.right_u()[i], p.y));
    // The matcher measured the column only: the raw right pixel agrees along the row.
    EXPECT_NEAR(raw_right.x(), raw_right_before[i].x(), 0.05);
  }
  EXPECT_GT(stereo, 50);
}

TEST_F(CalibrationApplyTest, AGyroScaleEstimateMovesTheChainsPreintegrationsAndBiases) {
  // A chain whose samples were corrected with no scale error; the estimate says the gyro reads
  // 0.5% fast about y: every keyframe's preintegration is re-integrated from samples divided by
  // 1.005 (and its gyro bias, a term of the same samples, with them).
  const PreintegratedImu pim =
      SetChain(ImuBias(Eigen::Vector3d(0.01, -0.02, 0.0), Eigen::Vector3d::Zero()));
  RigCalibration estimate = file_;
  estimate.gyro_scale = Eigen::Vector3d(0.0, 0.005, 0.0);
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kCalibration);
    MoveToCalibration(lock, &atlas_, estimate, setup_);
  }
  auto lock = MapReader(atlas_).Lock();
  EXPECT_EQ(atlas_.calibration().gyro_scale, estimate.gyro_scale);
  PreintegratedImu expected = pim;
  RescaleGyro(Eigen::Vector3d(1.0, 1.0 / 1.005, 1.0), &expected);
  const KeyFrame& kf = *map_.keyframes[4];
  ASSERT_TRUE(kf.imu().from_previous.has_value());
  EXPECT_NEAR(kf.imu().from_previous->steps[0].gyro.y(), 0.8 / 1.005, 1e-15);
  EXPECT_EQ(kf.imu().from_previous->delta_R.quaternion().coeffs(),
            expected.delta_R.quaternion().coeffs());
  EXPECT_NEAR(kf.imu().state.bias.gyro.y(), -0.02 / 1.005, 1e-15);
  // The rotation integrated about y is 0.5% smaller: 40 steps of (0.8 + 0.02) rad/s * 5 ms.
  EXPECT_NEAR((pim.delta_R.Inverse() * kf.imu().from_previous->delta_R).Angle(),
              0.164 * 0.005 / 1.005, 1e-5);
}

TEST_F(CalibrationApplyTest, AnAccelAxesEstimateMovesTheChainsPreintegrationsAndBiases) {
  // The estimate says the accelerometer reads 0.4% long on y with a 0.1 deg cross-axis term:
  // every keyframe's preintegration is re-integrated from samples multiplied by (I + E)^-1, and
  // its accelerometer bias with them; the gyro side stays.
  const Eigen::Vector3d bias_accel(0.05, -0.1, 0.02);
  const PreintegratedImu pim = SetChain(ImuBias(Eigen::Vector3d::Zero(), bias_accel));
  RigCalibration estimate = file_;
  estimate.accel_axes(1, 1) = 0.004;
  estimate.accel_axes(0, 1) = 0.1 * M_PI / 180.0;
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kCalibration);
    MoveToCalibration(lock, &atlas_, estimate, setup_);
  }
  auto lock = MapReader(atlas_).Lock();
  EXPECT_EQ(atlas_.calibration().accel_axes, estimate.accel_axes);
  const Eigen::Matrix3d m = (Eigen::Matrix3d::Identity() + estimate.accel_axes).inverse();
  const KeyFrame& kf = *map_.keyframes[4];
  ASSERT_TRUE(kf.imu().from_previous.has_value());
  EXPECT_TRUE(
      kf.imu().from_previous->steps[0].accel.isApprox(m * Eigen::Vector3d(0.1, 9.8, 0.2), 1e-15));
  EXPECT_TRUE(kf.imu().state.bias.accel.isApprox(m * bias_accel, 1e-15));
  EXPECT_EQ(kf.imu().from_previous->delta_R.quaternion().coeffs(),
            pim.delta_R.quaternion().coeffs());
  // 0.2 s of ~9.8 m/s^2 along y, 0.4% shorter: ~8 mm/s less velocity.
  EXPECT_NEAR((pim.delta_v - kf.imu().from_previous->delta_v).norm(), 0.2 * 9.9 * 0.004, 1e-3);
}

TEST_F(CalibrationApplyTest, AnAdjustmentOfAnExactMapMovesLittleAndAppliesCleanly) {
  CalibrationBundleProblem problem;
  {
    auto lock = MapReader(atlas_).Lock();
    problem = CollectCalibrationBundle(lock, map_.keyframes.back().get(), /*inertial=*/false,
                                       setup_, file_, file_, CalibrationCollectOptions{});
  }
  ASSERT_FALSE(problem.empty());
  EXPECT_FALSE(problem.inertial);
  problem.free.intrinsics = {true, true};
  problem.free.stereo_extrinsic = true;
  CalibrationBundleOptions options;
  options.covariance = false;
  const CalibrationBundleResult result = SolveCalibrationBundle(problem, options);
  // Noise-free observations of the file's own rig: the estimate stays at the file.
  EXPECT_NEAR(result.estimate.cameras[0].fx(), file_.cameras[0].fx(), 1e-3);
  EXPECT_NEAR(result.estimate.cameras[1].cx(), file_.cameras[1].cx(), 1e-3);
  const RigSetup next = BuildRig(result.estimate, StereoShape());
  const SE3d body_before = map_.keyframes[7]->world_from_body();
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kCalibration);
    ApplyCalibration(lock, &atlas_, atlas_.current_map(), problem, result, next);
  }
  EXPECT_GT(RefinePointsToCalibration(&atlas_, atlas_.current_map()->id()), -1);
  auto lock = MapReader(atlas_).Lock();
  EXPECT_LT((map_.keyframes[7]->world_from_body().Inverse() * body_before).Log().norm(), 1e-6);
  EXPECT_EQ(atlas_.current_map()->NumWorldChanges(), 1);  // tracking re-syncs
  for (const auto& [id, kf] : atlas_.current_map()->keyframes()) {
    EXPECT_EQ(kf->rig_ptr(), next.rig);
  }
}

TEST_F(CalibrationApplyTest, PointRefinementMovesPointsOntoTheirObservations) {
  // Points displaced by 2 cm come back to the scene (keyframe poses are exact).
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kFixture);
    for (const auto& [id, mp] : atlas_.current_map()->map_points()) {
      mp->SetPosition(lock, mp->position() + Eigen::Vector3d(0.02, -0.01, 0.015));
    }
  }
  EXPECT_GT(RefinePointsToCalibration(&atlas_, atlas_.current_map()->id()), 100);
  auto lock = MapReader(atlas_).Lock();
  double worst = 0;
  for (std::size_t p = 0; p < scene_.points_world.size(); ++p) {
    const MapPointPtr& mp = map_.point_of_scene_index[p];
    if (!mp || mp->IsBad()) continue;
    worst = std::max(worst, (mp->position() - scene_.points_world[p]).norm());
  }
  EXPECT_LT(worst, 1e-4);
}

}  // namespace
}  // namespace pkslam
