#include "viewer/view_data.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "core/util/error.h"
#include "io/rigid_transform_file.h"
#include "io/trajectory.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

std::filesystem::path RunFolder(const std::string& name, const std::string& stats) {
  const auto run = testing::MakeTempDir(name);
  std::ofstream(run / "trajectory.txt") << "0.0 0 0 0 0 0 0 1\n0.1 0.1 0 0 0 0 0 1\n";
  if (!stats.empty()) std::ofstream(run / "stats.json") << stats;
  return run;
}

// The page leads with the run's own warnings: degraded input and a suspect estimate.
TEST(LoadViewData, CarriesTheRunsWarnings) {
  ViewOptions options;
  options.run = RunFolder("view_warnings", R"({"degraded": true,
      "input": {"frames_skipped": 2, "warnings": ["2 frames skipped"]},
      "estimate": {"suspect": true, "warnings": ["tracking lost for good at t = 14.000 s"]}})");
  const ViewData data = LoadViewData(options);
  EXPECT_EQ(data.estimate.size(), 2u);
  EXPECT_THAT(data.warnings, ElementsAre("input: 2 frames skipped",
                                         "estimate: tracking lost for good at t = 14.000 s"));
  EXPECT_THAT(ViewDataJson(data), HasSubstr(R"("warnings":["input: 2 frames skipped",)"));
}

// Online calibration: its warning leads the page, its applied adjustments reach the timeline.
TEST(LoadViewData, CarriesTheOnlineCalibration) {
  ViewOptions options;
  options.run = RunFolder("view_calibration", R"({"calibration": {"mode": "online",
      "parameters": [{"name": "time_offset", "file": 0.0, "estimate": 1.01}],
      "warnings": ["time_offset in seq/mav0/cam0/sensor.yaml is -1.01 ms off the estimate"],
      "history": [{"t_s": 8.0, "applied": true, "estimate": {"time_offset": 0.7}},
                  {"t_s": 12.0, "applied": false, "estimate": {"time_offset": 0.7}},
                  {"t_s": 18.0, "applied": true, "estimate": {"time_offset": 1.0}}]}})");
  const ViewData data = LoadViewData(options);
  EXPECT_THAT(data.warnings, ElementsAre("calibration: time_offset in seq/mav0/cam0/sensor.yaml "
                                         "is -1.01 ms off the estimate"));
  ASSERT_EQ(data.calibration.size(), 2u);  // the applied ones
  EXPECT_DOUBLE_EQ(data.calibration[1].t_s, 18.0);
  EXPECT_DOUBLE_EQ(data.calibration[1].estimate.at("time_offset"), 1.0);
  EXPECT_DOUBLE_EQ(data.calibration_file.at("time_offset"), 0.0);
  EXPECT_THAT(ViewDataJson(data), HasSubstr(R"("calibration":[{"t":8,"e":{"time_offset":0.7}})"));
}

TEST(LoadViewData, NoStatsNoWarningsAndBadStatsNamed) {
  ViewOptions options;
  options.run = RunFolder("view_no_stats", "");
  EXPECT_TRUE(LoadViewData(options).warnings.empty());
  options.run = RunFolder("view_bad_stats", "{\"estimate\": [");
  try {
    LoadViewData(options);
    FAIL() << "a broken stats.json must be an error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("stats.json"));
  }
}

// Several runs and a bare trajectory in one page (issue 41), on a hand-made flight: body poses
// at 20 Hz, each held for two stamps, with an error of +e then -e along z on each pair (which
// leaves the alignment exact, so the ATE is e).
Trajectory Flight(double error) {
  Trajectory t;
  for (int k = 0; k < 40; ++k) {
    const double s = 0.1 * (k / 2);
    const double sign = k % 2 == 0 ? 1.0 : -1.0;
    t.poses.push_back({1403715274302142976LL + k * 50'000'000LL,
                       SE3d(SO3d::Exp(Eigen::Vector3d(0.1 * s, 0, 0.5 * s)),
                            Eigen::Vector3d(s, std::sin(s), 0.3 * s * s + sign * error))});
  }
  return t;
}

// A run folder of the flight with error e, in a map frame of its own: camera and body
// trajectories, the extrinsic, and every 10th pose as a keyframe.
std::filesystem::path FlightRun(const std::string& name, double error) {
  const auto run = testing::MakeTempDir(name) / "run";
  std::filesystem::create_directories(run);
  const SE3d body_from_camera(SO3d::Exp(Eigen::Vector3d(0.1, -0.2, 1.5)),
                              Eigen::Vector3d(0.05, -0.06, 0.01));
  const SE3d map_from_world(SO3d::Exp(Eigen::Vector3d(0.3, -0.2, 1.1)), Eigen::Vector3d(2, -1, 0));
  Trajectory body = Flight(error);
  for (StampedPose& p : body.poses) p.pose = map_from_world * p.pose;
  const Trajectory camera = ChangeSensorFrame(body, body_from_camera);
  WriteRigidTransform(body_from_camera, run / "body_from_camera.txt", "body_from_camera");
  WriteTrajectoryTum(body, run / "trajectory_body.txt");
  WriteTrajectoryTum(camera, run / "trajectory.txt");
  Trajectory keyframes;
  for (std::size_t i = 0; i < camera.poses.size(); i += 10) keyframes.poses.push_back(camera.poses[i]);
  WriteTrajectoryTum(keyframes, run / "keyframes.txt");
  return run;
}

TEST(LoadViewData, SeveralRunsAndABareTrajectoryShareTheGroundTruth) {
  const auto gt_dir = testing::MakeTempDir("view_multi_gt");
  WriteTrajectoryEuroc(Flight(0), gt_dir / "data.csv");
  ViewOptions options;
  options.run = FlightRun("view_multi_a", 0);
  options.ground_truth = gt_dir / "data.csv";
  options.more_runs = {FlightRun("view_multi_b", 0.01)};
  // The second run's body poses as ORB-SLAM3 writes them (nanosecond stamps, TUM columns).
  WriteTrajectory(ReadTrajectory(options.more_runs[0] / "trajectory_body.txt"),
                  gt_dir / "f_peer.txt", TrajectoryFormat::kOrbSlam3);
  options.trajectories = {{gt_dir / "f_peer.txt", "ORB-SLAM3", TrajectorySensorFrame::kBody},
                          {gt_dir / "f_peer.txt", "", TrajectorySensorFrame::kBody}};
  const ViewData data = LoadViewData(options);
  EXPECT_EQ(data.title, "run");
  EXPECT_NEAR(data.ate_rmse_m, 0, 1e-9);
  ASSERT_EQ(data.tracks.size(), 3u);
  EXPECT_EQ(data.tracks[0].label, "run (2)");  // both run folders are called "run"
  EXPECT_EQ(data.tracks[0].source, "run");
  EXPECT_EQ(data.tracks[0].alignment, "se3");
  EXPECT_NEAR(data.tracks[0].ate_rmse_m, 0.01, 1e-9);
  EXPECT_EQ(data.tracks[0].keyframes.size(), 4u);
  // Moved into the first run's camera, the body file gives the second run's camera ATE.
  EXPECT_EQ(data.tracks[1].label, "ORB-SLAM3");
  EXPECT_NEAR(data.tracks[1].ate_rmse_m, 0.01, 1e-9);
  EXPECT_EQ(data.tracks[2].label, "f_peer.txt");
  // Every track sits on the shown ground truth: the first pose within the error of the run's.
  for (const ViewTrack& t : data.tracks) {
    EXPECT_NEAR((t.estimate[0].world_from_camera.translation() -
                 data.estimate[0].world_from_camera.translation()).norm(), 0.01, 1e-9);
  }
  const std::string json = ViewDataJson(data);
  EXPECT_THAT(json, HasSubstr(R"j("tracks":[{"label":"run (2)","source":"run","alignment":"se3")j"));
  EXPECT_THAT(json, HasSubstr(R"({"label":"ORB-SLAM3","source":"trajectory")"));
}

TEST(LoadViewData, SeveralRunsNeedGroundTruthAndExistingFolders) {
  ViewOptions options;
  options.run = FlightRun("view_multi_nogt", 0);
  options.more_runs = {options.run};
  EXPECT_THROW(LoadViewData(options), OptionError);
  const auto gt_dir = testing::MakeTempDir("view_multi_missing");
  WriteTrajectoryEuroc(Flight(0), gt_dir / "data.csv");
  options.ground_truth = gt_dir / "data.csv";
  options.more_runs = {gt_dir / "no_such_run"};
  try {
    LoadViewData(options);
    FAIL() << "a missing run folder must be an error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("no_such_run: not a run folder"));
  }
}

}  // namespace
}  // namespace pkslam
