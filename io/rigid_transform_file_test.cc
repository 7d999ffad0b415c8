#include "io/rigid_transform_file.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

class RigidTransformFileTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::MakeTempDir("rigid_transform_test"); }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path Write(const std::string& content) {
    const fs::path file = dir_ / "t.txt";
    std::ofstream(file) << content;
    return file;
  }

  // The line of the InputError reading `content` throws (0: no line); -1 when none is thrown.
  long ErrorLine(const std::string& content) {
    try {
      ReadRigidTransform(Write(content));
    } catch (const InputError& e) {
      return static_cast<long>(e.line());
    }
    return -1;
  }

  fs::path dir_;
};

TEST_F(RigidTransformFileTest, RoundTrip) {
  const SE3d t(SO3d::Exp(Eigen::Vector3d(0.3, -1.2, 2.0)), Eigen::Vector3d(-0.02, -0.06, 0.01));
  const fs::path file = dir_ / "body_from_camera.txt";
  WriteRigidTransform(t, file, "body_from_camera");
  const SE3d back = ReadRigidTransform(file);
  EXPECT_LT((back.translation() - t.translation()).norm(), 1e-11);
  EXPECT_LT((back.so3().Inverse() * t.so3()).Log().norm(), 1e-11);
}

TEST_F(RigidTransformFileTest, BadContentNamesTheLine) {
  const std::string identity = "1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";
  EXPECT_EQ(ErrorLine("# c\n" + identity), -1);
  EXPECT_EQ(ErrorLine("# c\n1 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"), 2);  // three fields
  EXPECT_EQ(ErrorLine("1 0 0 0\n0 x 0 0\n0 0 1 0\n0 0 0 1\n"), 2);     // not a number
  EXPECT_EQ(ErrorLine(identity + "0 0 0 1\n"), 5);                     // a fifth row
  EXPECT_EQ(ErrorLine("1 0 0 0\n0 1 0 0\n0 0 1 0\n"), 0);              // three rows
  EXPECT_EQ(ErrorLine("1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 1 1\n"), 4);     // not 0 0 0 1
  EXPECT_EQ(ErrorLine("2 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"), 0);     // not a rotation
  EXPECT_EQ(ErrorLine("-1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"), 0);    // a reflection
  EXPECT_THROW(ReadRigidTransform(dir_ / "missing.txt"), InputError);
}

TEST_F(RigidTransformFileTest, ChangeSensorFrameComposesOnTheRight) {
  Trajectory body;
  body.poses.push_back({10, SE3d(SO3d::Exp(Eigen::Vector3d(0, 0, 1.5)), Eigen::Vector3d(1, 2, 3))});
  body.poses.push_back({20, SE3d()});
  body.extras.resize(2);
  const SE3d body_from_camera(SO3d(), Eigen::Vector3d(0.1, 0, 0));
  const Trajectory camera = ChangeSensorFrame(body, body_from_camera);
  ASSERT_EQ(camera.size(), 2u);
  EXPECT_FALSE(camera.has_extras());
  EXPECT_EQ(camera.poses[0].t_ns, 10);
  // The camera sits 0.1 m along the body's x axis, which the body's yaw of 1.5 rad turns.
  const Eigen::Vector3d expected(1 + 0.1 * std::cos(1.5), 2 + 0.1 * std::sin(1.5), 3);
  EXPECT_LT((camera.poses[0].pose.translation() - expected).norm(), 1e-12);
  EXPECT_LT((camera.poses[1].pose.translation() - Eigen::Vector3d(0.1, 0, 0)).norm(), 1e-12);
}

}  // namespace
}  // namespace pkslam
