#include "imu/body_reprojection_error.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "core/geometry/lie_test_utils.h"
#include "imu/imu_manifolds.h"
#include "imu/imu_test_utils.h"

namespace pkslam {
namespace {

using testing::CompareJacobians;
using testing::RandomTangent;
using Vec3 = Eigen::Vector3d;
using Block = std::vector<double>;

// EuRoC-like camera: looking along the body's x axis, 5 cm off, 11 cm baseline.
BodyCamera TestCamera() {
  BodyCamera cam;
  cam.fx = 458.0;
  cam.fy = 457.0;
  cam.cx = 367.0;
  cam.cy = 248.0;
  cam.bf = 0.11 * cam.fx;
  const SO3d body_from_camera_rot((Eigen::Matrix3d() << 0, 0, 1, -1, 0, 0, 0, -1, 0).finished());
  const SE3d body_from_camera(body_from_camera_rot * SO3d::Exp(Vec3(0.01, -0.02, 0.015)),
                              Vec3(-0.02, -0.06, 0.01));
  cam.camera_from_body = body_from_camera.Inverse();
  return cam;
}

struct CameraScene {
  BodyCamera cam = TestCamera();
  SE3d world_from_body;
  Vec3 p_world;
  CameraScene() {
    std::mt19937 rng(12);
    world_from_body = SE3d::Exp(RandomTangent<6>(rng, 1.0));
    // A point 4 m in front of the camera, a little off-axis.
    const SE3d world_from_camera = world_from_body * cam.camera_from_body.Inverse();
    p_world = world_from_camera * Vec3(0.4, -0.3, 4.0);
  }
  Block PoseBlock() const {
    Block b(7);
    BodyPoseToBlock(world_from_body, b.data());
    return b;
  }
  Block PointBlock() const { return {p_world.x(), p_world.y(), p_world.z()}; }
  // Projection through camera_from_world = camera_from_body * body_from_world.
  Vec3 Projection() const {
    const Vec3 p = cam.camera_from_body * (world_from_body.Inverse() * p_world);
    const double u = cam.fx * p.x() / p.z() + cam.cx;
    return {u, cam.fy * p.y() / p.z() + cam.cy, u - cam.bf / p.z()};
  }
};

void ExpectMatch(const std::vector<testing::JacobianPair>& pairs, std::size_t n) {
  ASSERT_EQ(pairs.size(), n);
  for (std::size_t i = 0; i < n; ++i) {
    const double scale = 1.0 + pairs[i].analytic.cwiseAbs().maxCoeff();
    EXPECT_LT((pairs[i].analytic - pairs[i].numeric).cwiseAbs().maxCoeff(), 1e-6 * scale)
        << "block " << i << "\n"
        << pairs[i].analytic << "\n\n"
        << pairs[i].numeric;
  }
}

TEST(BodyReprojectionError, ResidualIsWhitenedProjectionError) {
  const CameraScene s;
  const Vec3 proj = s.Projection();
  const Eigen::Vector2d obs(proj.x() + 2.0, proj.y() - 1.0);
  const double inv_sigma2 = 1.0 / (1.2 * 1.2);
  const BodyMonoReprojectionError mono(s.cam, obs, inv_sigma2);
  const Block pose = s.PoseBlock(), point = s.PointBlock();
  const double* params[] = {pose.data(), point.data()};
  Eigen::Vector2d r;
  ASSERT_TRUE(mono.Evaluate(params, r.data(), nullptr));
  EXPECT_NEAR(r.x(), -2.0 / 1.2, 1e-9);
  EXPECT_NEAR(r.y(), 1.0 / 1.2, 1e-9);
  EXPECT_NEAR(BodyMonoChi2(s.cam, s.world_from_body, s.p_world, obs, inv_sigma2), r.squaredNorm(),
              1e-9);
  const Vec3 obs3(proj.x(), proj.y(), proj.z() + 0.5);
  const BodyStereoReprojectionError stereo(s.cam, obs3, 1.0);
  Vec3 r3;
  ASSERT_TRUE(stereo.Evaluate(params, r3.data(), nullptr));
  EXPECT_NEAR(r3.z(), -0.5, 1e-9);
  EXPECT_NEAR(BodyStereoChi2(s.cam, s.world_from_body, s.p_world, obs3, 1.0), 0.25, 1e-9);
}

TEST(BodyReprojectionError, JacobiansMatchNumeric) {
  const CameraScene s;
  const BodyPoseManifold pose_manifold;
  const Vec3 proj = s.Projection();
  const Eigen::Vector2d obs2(proj.x() + 3, proj.y() + 2);
  const Vec3 obs3(proj.x() + 3, proj.y() + 2, proj.z() - 1);
  const Block pose = s.PoseBlock(), point = s.PointBlock();
  ExpectMatch(CompareJacobians(BodyMonoReprojectionError(s.cam, obs2, 0.7), {pose, point},
                               {&pose_manifold, nullptr}),
              2);
  ExpectMatch(CompareJacobians(BodyStereoReprojectionError(s.cam, obs3, 0.7), {pose, point},
                               {&pose_manifold, nullptr}),
              2);
  ExpectMatch(CompareJacobians(BodyMonoPoseOnlyError(s.cam, s.p_world, obs2, 0.7), {pose},
                               {&pose_manifold}),
              1);
  ExpectMatch(CompareJacobians(BodyStereoPoseOnlyError(s.cam, s.p_world, obs3, 0.7), {pose},
                               {&pose_manifold}),
              1);
}

TEST(BodyReprojectionError, PointBehindCameraFails) {
  const CameraScene s;
  const SE3d world_from_camera = s.world_from_body * s.cam.camera_from_body.Inverse();
  const Vec3 behind = world_from_camera * Vec3(0.1, 0.1, -2.0);
  const BodyMonoPoseOnlyError cost(s.cam, behind, Eigen::Vector2d(300, 200), 1.0);
  const Block pose = s.PoseBlock();
  const double* params[] = {pose.data()};
  Eigen::Vector2d r;
  EXPECT_FALSE(cost.Evaluate(params, r.data(), nullptr));
  EXPECT_TRUE(
      std::isinf(BodyMonoChi2(s.cam, s.world_from_body, behind, Eigen::Vector2d(300, 200), 1.0)));
}

}  // namespace
}  // namespace pkslam
