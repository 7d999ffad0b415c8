// End-to-end: `pkslam simulate` replays real EuRoC ground truth (with IMU noise and biases),
// `pkslam run --sensor stereo-inertial` tracks it, and the body trajectory meets the
// stereo-inertial accuracy bar against the simulator's ground truth.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "evaluation/evaluate.h"
#include "io/trajectory.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

using ::testing::HasSubstr;

using testing::RunPkslam;

TEST(InertialRun, StereoInertialSimulatedReplayMeetsAteBar) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const auto dir = testing::MakeTempDir("inertial_run");
  const auto seq = dir / "seq";
  const auto out = dir / "out";
  const auto sim = RunPkslam(fmt::format(
      "--log-level warn simulate --out '{}' --trajectory '{}' --start 5 --duration 8 "
      "--quality fast --quiet --no-cloud --realism ideal --gyro-bias 0.002,-0.003,0.001 "
      "--accel-bias 0.05,-0.03,0.04",
      seq.string(), (shared / "euroc/groundtruth/V1_02_medium.txt").string()));
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const auto run = RunPkslam(
      fmt::format("--log-level info run --dataset '{}' --sensor stereo-inertial --out '{}' --quiet "
                  "--deterministic",
                  seq.string(), out.string()));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("IMU initialisation"));

  const Trajectory gt = ReadTrajectory(seq / "mav0/state_groundtruth_estimate0/data.csv");
  const Trajectory est = ReadTrajectory(out / "trajectory_body.txt");
  EvaluationOptions options;
  options.alignment = AlignmentMethod::kSE3;
  options.compute_rpe = false;
  const EvaluationResult r = EvaluateTrajectories(gt, est, options);
  // Nearly every frame is in the trajectory and the body trajectory meets the 3 cm bar.
  EXPECT_GT(r.pairs.size(), 150u);
  EXPECT_LT(r.ate_translation_m.rmse, 0.03) << "ATE " << r.ate_translation_m.rmse;
  ::testing::Test::RecordProperty("ate_rmse_m", std::to_string(r.ate_translation_m.rmse));

  // The map's IMU was initialised and the last keyframes carry estimated biases.
  std::ifstream imu_csv(out / "keyframes_imu.csv");
  ASSERT_TRUE(imu_csv.good());
  std::string line;
  std::string last;
  while (std::getline(imu_csv, line)) last = line;
  EXPECT_THAT(last, ::testing::EndsWith(",1,1"));
}

}  // namespace
}  // namespace pkslam
