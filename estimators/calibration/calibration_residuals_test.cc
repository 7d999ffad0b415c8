#include "estimators/calibration/calibration_residuals.h"

#include <gtest/gtest.h>

#include "core/camera/test_cameras.h"
#include "estimators/optim/se3_manifold.h"
#include "imu/imu_manifolds.h"
#include "imu/imu_test_utils.h"

namespace pkslam {
namespace {

std::vector<double> Block(const SE3d& t, bool body) {
  std::vector<double> b(7);
  body ? BodyPoseToBlock(t, b.data()) : PoseToBlock(t, b.data());
  return b;
}

std::vector<double> Intrinsics(const CameraModel& camera) {
  const auto k = IntrinsicsBlock(camera);
  return {k.begin(), k.end()};
}

// A keyframe looking at a point 3 m ahead of cam0, mid-turn and moving, its image 1.2 ms after
// its state (offset 1.5 ms, 0.3 ms applied).
struct Keyframe {
  SE3d world_from_body = SE3d::Exp((Eigen::Matrix<double, 6, 1>() << 0.3, -0.2, 1.1, 0.2, -0.4,
                                    0.9).finished());
  SE3d cam0_from_body = testing::EurocBodyFromCam0().Inverse();
  SE3d cam1_from_cam0 = testing::EurocCam1FromCam0();
  ImageTiming timing{Eigen::Vector3d(0.4, -0.7, 0.3), 0.3e-3};
  Eigen::Vector3d point() const {
    return world_from_body * (cam0_from_body.Inverse() * Eigen::Vector3d(0.4, -0.3, 3.0));
  }
};

void ExpectJacobiansMatch(const std::vector<testing::JacobianPair>& pairs) {
  ASSERT_FALSE(pairs.empty());
  for (std::size_t b = 0; b < pairs.size(); ++b) {
    const double scale = std::max(1.0, pairs[b].numeric.cwiseAbs().maxCoeff());
    EXPECT_LT((pairs[b].analytic - pairs[b].numeric).cwiseAbs().maxCoeff(), 1e-5 * scale)
        << "block " << b << "\nanalytic\n"
        << pairs[b].analytic << "\nnumeric\n"
        << pairs[b].numeric;
  }
}

TEST(CalibrationResidualsTest, LeftJacobiansMatchNumericDifferentiation) {
  const Keyframe s;
  const CameraModel cam0 = testing::EurocCam0();
  const CalibratedLeftError cost(Eigen::Vector2d(400, 250), Eigen::Matrix2d::Identity() * 0.8,
                                 FixedDistortionOf(cam0), s.timing);
  const BodyPoseManifold body;
  const SE3LeftManifold left;
  const Eigen::Vector3d x = s.point();
  ExpectJacobiansMatch(testing::CompareJacobians(
      cost,
      {Block(s.world_from_body, true), {x.x(), x.y(), x.z()}, Intrinsics(cam0),
       Block(s.cam0_from_body, false), {1.5e-3}, {0.8, -0.3, 0.2}},
      {&body, nullptr, nullptr, &left, nullptr, nullptr}));
}

TEST(CalibrationResidualsTest, RightJacobiansMatchNumericDifferentiation) {
  const Keyframe s;
  const CameraModel cam1 = testing::EurocCam1();
  const CalibratedRightError cost(Eigen::Vector2d(380, 240), Eigen::RowVector2d(0.9, 0.05),
                                  FixedDistortionOf(cam1), s.timing, Eigen::Vector2d(-1.1, 6.9));
  const BodyPoseManifold body;
  const SE3LeftManifold left;
  const Eigen::Vector3d x = s.point();
  ExpectJacobiansMatch(testing::CompareJacobians(
      cost,
      {Block(s.world_from_body, true), {x.x(), x.y(), x.z()}, Intrinsics(cam1),
       Intrinsics(testing::EurocCam0()), Block(s.cam0_from_body, false),
       Block(s.cam1_from_cam0, false), {1.5e-3}, {0.8, -0.3, 0.2}},
      {&body, nullptr, nullptr, nullptr, &left, &left, nullptr, nullptr}));
}

TEST(CalibrationResidualsTest, ResidualIsZeroAtTheTrueProjectionOfTheImageTime) {
  // The image taken `delta` after the state shows the body turned by omega * delta and moved by
  // v * delta: projecting that pose with the camera model gives the measurement exactly.
  const Keyframe s;
  const CameraModel cam0 = testing::EurocCam0();
  const double offset = 1.5e-3;
  const double delta = offset - s.timing.offset_applied;
  const Eigen::Vector3d v(0.8, -0.3, 0.2);
  const SE3d at_image(s.world_from_body.so3() * SO3d::Exp(s.timing.angular_velocity * delta),
                      s.world_from_body.translation() + v * delta);
  const Eigen::Vector3d x = s.point();
  const auto uv = cam0.Project(s.cam0_from_body * (at_image.Inverse() * x));
  ASSERT_TRUE(uv.has_value());
  const CalibratedLeftError cost(*uv, Eigen::Matrix2d::Identity(), FixedDistortionOf(cam0),
                                 s.timing);
  const auto pose = Block(s.world_from_body, true);
  const auto k = Intrinsics(cam0);
  const auto ext = Block(s.cam0_from_body, false);
  const double point[3] = {x.x(), x.y(), x.z()};
  const double* params[6] = {pose.data(), point, k.data(), ext.data(), &offset, v.data()};
  double r[2];
  ASSERT_TRUE(cost.Evaluate(params, r, nullptr));
  EXPECT_NEAR(r[0], 0.0, 1e-9);
  EXPECT_NEAR(r[1], 0.0, 1e-9);
}

TEST(CalibrationResidualsTest, ExtrinsicPriorJacobianMatches) {
  const SE3d mean = testing::EurocCam1FromCam0();
  const ExtrinsicPriorError cost(mean, 1e-3, 1e-3);
  const SE3LeftManifold left;
  const SE3d moved = SE3d::Exp((Eigen::Matrix<double, 6, 1>() << 2e-3, -1e-3, 0, 3e-3, 0, -2e-3)
                                   .finished()) *
                     mean;
  ExpectJacobiansMatch(testing::CompareJacobians(cost, {Block(moved, false)}, {&left}));
}

}  // namespace
}  // namespace pkslam
