// Visual-inertial pose optimisation on values: a body on the analytic helix, seen through a
// monocular camera with a tenth of its observations moved, and the exact preintegration from
// the previous state. The solve must recover the state, flag exactly the moved observations,
// and return a usable (symmetric, positive) marginal information.
#include "estimators/inertial/inertial_pose_solve.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>
#include <vector>

#include "core/util/error.h"
#include "imu/imu_test_utils.h"
#include "imu/preintegration.h"

namespace pkslam {
namespace {

using testing::HelixMotion;
using testing::Seconds;

constexpr std::int64_t kPreviousNs = 1'000'000'000;
constexpr std::int64_t kFrameNs = 1'050'000'000;  // 20 Hz camera
constexpr std::int64_t kImuPeriodNs = 5'000'000;  // 200 Hz

struct InertialPoseCase {
  BodyCamera camera;
  NavState truth;
  NavState previous;
  PreintegratedImu preintegration;
  std::vector<PoseCorrespondence> correspondences;
  std::vector<bool> is_outlier;
};

// 300 points 2-8 m in front of the camera at the frame's true pose, 0.5 px noise, every
// `outlier_every`-th observation moved by 40 px; zero biases, noise-free IMU samples.
InertialPoseCase MakeCase(int outlier_every, std::uint64_t seed) {
  InertialPoseCase c;
  c.camera.fx = c.camera.fy = 450;
  c.camera.cx = 376;
  c.camera.cy = 240;
  c.camera.camera_from_body =
      SE3d(SO3d::Exp(Eigen::Vector3d(0.05, -1.5, 0.02)), Eigen::Vector3d(0.02, -0.06, 0.01));
  const HelixMotion motion;
  c.truth = motion.State(Seconds(kFrameNs));
  c.previous = motion.State(Seconds(kPreviousNs));
  const std::vector<ImuMeasurement> samples =
      testing::SampleImu(motion, 0, 2 * kFrameNs, kImuPeriodNs, ImuBias{}, ImuNoise{}, nullptr);
  c.preintegration = StartPreintegration(ImuBias{}, ImuNoise{});
  IntegrateSamples(samples, kPreviousNs, kFrameNs, &c.preintegration);

  std::mt19937 rng(static_cast<std::mt19937::result_type>(seed));
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> depth(2.0, 8.0);
  std::normal_distribution<double> pixel(0.0, 0.5);
  const SE3d world_from_camera = c.truth.world_from_body * c.camera.camera_from_body.Inverse();
  for (int i = 0; i < 300; ++i) {
    const double z = depth(rng);
    const Eigen::Vector3d p_camera(unit(rng) * 0.7 * z, unit(rng) * 0.45 * z, z);
    PoseCorrespondence& p = c.correspondences.emplace_back();
    p.keypoint = i;
    p.p_world = world_from_camera * p_camera;
    const bool outlier = outlier_every > 0 && i % outlier_every == 0;
    const Eigen::Vector2d uv(c.camera.fx * p_camera.x() / z + c.camera.cx + pixel(rng),
                             c.camera.fy * p_camera.y() / z + c.camera.cy + pixel(rng));
    const Eigen::Vector2d moved =
        uv + (outlier ? Eigen::Vector2d(40, -40) : Eigen::Vector2d::Zero().eval());
    p.obs = Eigen::Vector3d(moved.x(), moved.y(), -1.0);
    p.inv_sigma2 = 1.0;
    c.is_outlier.push_back(outlier);
  }
  return c;
}

InertialPoseInput FixedPrevious(const InertialPoseCase& c) {
  InertialPoseInput input;
  input.previous_state = c.previous;
  input.preintegration = &c.preintegration;
  input.gravity_world = testing::kTestGravity;
  return input;
}

TEST(SolveInertialPoseTest, RecoversTheStateAndFlagsTheMovedObservations) {
  InertialPoseCase c = MakeCase(10, 3);
  // Start 5 cm, ~1.7 degrees and 0.2 m/s off.
  NavState start = c.truth;
  start.world_from_body =
      SE3d(SO3d::Exp(Eigen::Vector3d(0.0, 0.03, 0.0)), Eigen::Vector3d(0.05, 0.0, 0.0)) *
      c.truth.world_from_body;
  start.velocity_world += Eigen::Vector3d(0.2, -0.1, 0.0);
  const InertialPoseOutput out =
      SolveInertialPose(c.camera, start, ImuBias{}, &c.correspondences, FixedPrevious(c), {});
  EXPECT_LT(
      (out.state.world_from_body.translation() - c.truth.world_from_body.translation()).norm(),
      0.01);
  EXPECT_LT(
      (out.state.world_from_body.so3().Inverse() * c.truth.world_from_body.so3()).Log().norm(),
      0.002);
  EXPECT_LT((out.state.velocity_world - c.truth.velocity_world).norm(), 0.02);
  int wrong = 0;
  for (std::size_t i = 0; i < c.correspondences.size(); ++i) {
    wrong += (c.correspondences[i].block == nullptr) != c.is_outlier[i] ? 1 : 0;
  }
  EXPECT_EQ(wrong, 0);
  EXPECT_EQ(out.inliers, 270);
}

TEST(SolveInertialPoseTest, FreePreviousStateGivesASymmetricPositiveMarginal) {
  InertialPoseCase c = MakeCase(0, 4);
  InertialPoseInput input = FixedPrevious(c);
  input.previous_information = 1e4 * InertialInformation::Identity();
  const InertialPoseOutput out =
      SolveInertialPose(c.camera, c.truth, ImuBias{}, &c.correspondences, input, {});
  EXPECT_EQ(out.inliers, 300);
  EXPECT_LT((out.information - out.information.transpose()).norm(), 1e-9 * out.information.norm());
  const Eigen::SelfAdjointEigenSolver<InertialInformation> es(out.information);
  EXPECT_GT(es.eigenvalues().minCoeff(), 0.0);
  // The previous state's prior bounds what the frame may know: marginalising it out leaves
  // less information on the frame's velocity than with the previous state held fixed.
  InertialPoseCase fixed_case = MakeCase(0, 4);
  const InertialPoseOutput fixed =
      SolveInertialPose(fixed_case.camera, fixed_case.truth, ImuBias{}, &fixed_case.correspondences,
                        FixedPrevious(fixed_case), {});
  const double velocity_free = out.information.block<3, 3>(6, 6).trace();
  const double velocity_fixed = fixed.information.block<3, 3>(6, 6).trace();
  EXPECT_LT(velocity_free, velocity_fixed);
}

TEST(SolveInertialPoseTest, SameInputSameOutputAndChecksItsInput) {
  InertialPoseCase a = MakeCase(7, 5);
  InertialPoseCase b = MakeCase(7, 5);
  const InertialPoseOutput ra =
      SolveInertialPose(a.camera, a.truth, ImuBias{}, &a.correspondences, FixedPrevious(a), {});
  const InertialPoseOutput rb =
      SolveInertialPose(b.camera, b.truth, ImuBias{}, &b.correspondences, FixedPrevious(b), {});
  EXPECT_EQ(ra.state.world_from_body.Matrix(), rb.state.world_from_body.Matrix());
  EXPECT_EQ(ra.information, rb.information);
  InertialPoseInput no_imu = FixedPrevious(a);
  no_imu.preintegration = nullptr;
  EXPECT_THROW(SolveInertialPose(a.camera, a.truth, ImuBias{}, &a.correspondences, no_imu, {}),
               Error);
  PoseOptimizerOptions bad;
  bad.rounds = 0;
  EXPECT_THROW(
      SolveInertialPose(a.camera, a.truth, ImuBias{}, &a.correspondences, FixedPrevious(a), bad),
      OptionError);
}

}  // namespace
}  // namespace pkslam
