#include "viewer/view_tracks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "core/util/error.h"
#include "io/rigid_transform_file.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

using ::testing::HasSubstr;

constexpr std::int64_t kT0 = 1403715274302142976;  // EuRoC-like nanosecond stamps
constexpr double kError = 0.01;                     // m

// A hand-made flight of body poses at 20 Hz, turning and climbing, each pose held for two
// stamps. An error of +kError then -kError along z on each pair leaves the alignment exact (the
// error has no cross-covariance with the path), so the ATE is kError on every pose.
Trajectory TracksFlight(double error) {
  Trajectory t;
  for (int k = 0; k < 40; ++k) {
    const double s = 0.1 * (k / 2);
    const Eigen::Vector3d p(s, std::sin(s), 0.3 * s * s);
    const double sign = k % 2 == 0 ? 1.0 : -1.0;
    t.poses.push_back({kT0 + k * 50'000'000LL,
                       SE3d(SO3d::Exp(Eigen::Vector3d(0.1 * s, 0, 0.5 * s)),
                            p + Eigen::Vector3d(0, 0, sign * error))});
  }
  return t;
}

// Every pose moved by a rigid transform: the same flight in another world.
Trajectory InOtherWorld(Trajectory t) {
  const SE3d other_from_world(SO3d::Exp(Eigen::Vector3d(0.3, -0.2, 1.1)),
                              Eigen::Vector3d(2, -1, 0.5));
  for (StampedPose& p : t.poses) p.pose = other_from_world * p.pose;
  return t;
}

const SE3d& BodyFromCamera() {
  static const SE3d t(SO3d::Exp(Eigen::Vector3d(0.1, -0.2, 1.5)),
                      Eigen::Vector3d(0.05, -0.06, 0.01));
  return t;
}

TEST(AlignToGroundTruth, HandMadeErrorGivesItsAte) {
  const AlignedEstimate a =
      AlignToGroundTruth(TracksFlight(0), InOtherWorld(TracksFlight(kError)), AlignmentMethod::kSE3);
  EXPECT_NEAR(a.ate_rmse_m, kError, 1e-9);
  ASSERT_EQ(a.poses.size(), 40u);
  const Trajectory truth = TracksFlight(0);
  for (std::size_t i = 0; i < a.poses.size(); ++i) {
    EXPECT_NEAR(a.poses[i].ate_m, kError, 1e-9);
    // Back in the ground truth's world.
    EXPECT_NEAR((a.poses[i].world_from_camera.translation() -
                 truth.poses[i].pose.translation()).norm(), kError, 1e-9);
  }
}

// A body trajectory (ORB-SLAM3's f_*.txt format) is moved into the camera the first run is
// compared in: against the ground truth moved there too, only the hand-made error remains.
TEST(LoadTrajectoryTrack, BodyPosesMovedIntoTheRunsCamera) {
  const auto dir = testing::MakeTempDir("view_track_body");
  WriteRigidTransform(BodyFromCamera(), dir / "body_from_camera.txt", "body_from_camera");
  WriteTrajectory(InOtherWorld(TracksFlight(kError)), dir / "f_peer.txt", TrajectoryFormat::kOrbSlam3);
  const Trajectory camera_truth = ChangeSensorFrame(TracksFlight(0), BodyFromCamera());

  ViewTrajectoryFile file{dir / "f_peer.txt", "", TrajectorySensorFrame::kBody};
  const ViewTrack body = LoadTrajectoryTrack(file, camera_truth, /*shown_in_camera=*/true, dir,
                                             AlignmentMethod::kSE3);
  EXPECT_EQ(body.label, "f_peer.txt");
  EXPECT_EQ(body.source, "trajectory");
  EXPECT_EQ(body.alignment, "se3");
  EXPECT_EQ(body.estimate.size(), 40u);
  EXPECT_TRUE(body.keyframes.empty());
  EXPECT_NEAR(body.ate_rmse_m, kError, 1e-9);

  // Taken as camera poses they stay a turning lever arm off the path.
  file.frame = TrajectorySensorFrame::kCamera;
  file.label = "peer";
  const ViewTrack camera = LoadTrajectoryTrack(file, camera_truth, true, dir,
                                               AlignmentMethod::kSE3);
  EXPECT_EQ(camera.label, "peer");
  EXPECT_GT(camera.ate_rmse_m, kError + 0.005);

  // Camera poses against a body-frame comparison go the other way through the extrinsic.
  WriteTrajectory(InOtherWorld(ChangeSensorFrame(TracksFlight(kError), BodyFromCamera())),
                  dir / "camera.txt", TrajectoryFormat::kTum);
  file.file = dir / "camera.txt";
  EXPECT_NEAR(LoadTrajectoryTrack(file, TracksFlight(0), /*shown_in_camera=*/false, dir,
                                  AlignmentMethod::kSE3)
                  .ate_rmse_m,
              kError, 1e-9);
}

TEST(LoadTrajectoryTrack, MissingFilesAreNamed) {
  const auto dir = testing::MakeTempDir("view_track_missing");
  WriteTrajectory(TracksFlight(0), dir / "f.txt", TrajectoryFormat::kTum);
  ViewTrajectoryFile file{dir / "absent.txt", "", TrajectorySensorFrame::kBody};
  auto message = [&] {
    try {
      LoadTrajectoryTrack(file, TracksFlight(0), true, dir, AlignmentMethod::kSE3);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(message(), HasSubstr("absent.txt: not found (--trajectory)"));
  file.file = dir / "f.txt";  // body poses, camera comparison, no body_from_camera.txt
  EXPECT_THAT(message(), HasSubstr("body_from_camera.txt is missing"));
  std::ofstream(dir / "bad.txt") << "not a trajectory\n";
  file.file = dir / "bad.txt";
  EXPECT_THAT(message(), HasSubstr("bad.txt"));
}

TEST(RunFolderName, LastComponentAlsoWithTrailingSeparator) {
  EXPECT_EQ(RunFolderName("/tmp/a/run"), "run");
  EXPECT_EQ(RunFolderName("/tmp/a/run/"), "run");
  // A bench run folder, named by its index, keeps its configuration.
  EXPECT_EQ(RunFolderName("/tmp/bench/runs/V101/stereo/pks/seed2"), "pks/seed2");
  EXPECT_EQ(RunFolderName("/tmp/a/seedling"), "seedling");
}

}  // namespace
}  // namespace pkslam
