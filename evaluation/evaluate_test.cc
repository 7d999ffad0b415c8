#include "evaluation/evaluate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

// Relative agreement to better than 5 in the 5th significant digit.
void ExpectClose(double actual, double published, const char* what) {
  EXPECT_NEAR(actual, published, 5e-5 * std::abs(published) + 1e-7) << what;
}

Trajectory Synthetic(std::size_t n, std::int64_t t0_ns, std::int64_t step_ns) {
  Trajectory traj;
  for (std::size_t i = 0; i < n; ++i) {
    const double s = static_cast<double>(i);
    traj.poses.push_back({t0_ns + static_cast<std::int64_t>(i) * step_ns,
                          SE3d(SO3d::Exp(Eigen::Vector3d(0.01 * s, 0.02, -0.03 * s)),
                               Eigen::Vector3d(std::cos(0.1 * s), std::sin(0.13 * s), 0.05 * s))});
  }
  return traj;
}

// Published by the evo project for its test data (see ../shared/data/README.md).
TEST(EvaluateTrajectories, ReproducesEvoOnFr2DeskOrb) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const Trajectory gt = ReadTrajectory(shared / "evo" / "fr2_desk_groundtruth.txt");
  const Trajectory est = ReadTrajectory(shared / "evo" / "fr2_desk_ORB.txt");
  EvaluationOptions options;
  options.alignment = AlignmentMethod::kSE3;
  const EvaluationResult r = EvaluateTrajectories(gt, est, options);
  ExpectClose(r.ate_translation_m.rmse, 0.008119, "rmse");
  ExpectClose(r.ate_translation_m.mean, 0.007492, "mean");
  ExpectClose(r.ate_translation_m.max, 0.024300, "max");
  ExpectClose(r.ate_translation_m.sse, 0.143305, "sse");
  EXPECT_EQ(r.scale(), 1.0);
  // evo's own association (with its repeated matches) gives the same pairs here.
  options.association.one_to_one = false;
  EXPECT_EQ(EvaluateTrajectories(gt, est, options).pairs, r.pairs);
}

// An estimate that repeats a stamp with two poses (ORB-SLAM3 does this now and then): evo pairs
// both with the nearest reference pose and both count in the ATE.
TEST(EvaluateTrajectories, RepeatedEstimateStampsCountAsInEvo) {
  const auto dir = testing::MakeTempDir("eval_repeats");
  {
    std::ofstream gt(dir / "gt.txt");
    for (int i = 0; i < 10; ++i) gt << i << ".0 " << i << " 0 0 0 0 0 1\n";
    std::ofstream est(dir / "est.txt");
    est << "1.0 1 0 0 0 0 0 1\n1.0 1.3 0 0 0 0 0 1\n2.0 2 0 0 0 0 0 1\n";
  }
  const Trajectory gt = ReadTrajectory(dir / "gt.txt");
  const Trajectory est =
      ReadTrajectory(dir / "est.txt", TrajectoryFormat::kAuto, DuplicateTimestamps::kKeepAll);
  ASSERT_EQ(est.size(), 3u);
  EvaluationOptions options;
  options.alignment = AlignmentMethod::kNone;
  const EvaluationResult r = EvaluateTrajectories(gt, est, options);
  ASSERT_EQ(r.pairs.size(), 3u);
  // Errors 0, 0.3 and 0 m: rmse = sqrt(0.09 / 3).
  EXPECT_NEAR(r.ate_translation_m.rmse, std::sqrt(0.03), 1e-9);
  EXPECT_NEAR(r.ate_translation_m.max, 0.3, 1e-9);
  // Dropping the repeat (the older reading) would have hidden the 0.3 m error.
  EXPECT_EQ(ReadTrajectory(dir / "est.txt").size(), 2u);
}

TEST(EvaluateTrajectories, RepeatedReferenceStampsKeptGiveEvoResultsToo) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  // fr2_desk ground truth repeats 1311868229.5760: kept or dropped, the nearest-time search
  // takes the first pose of the two, as evo's argmin does.
  const Trajectory gt = ReadTrajectory(shared / "evo" / "fr2_desk_groundtruth.txt",
                                       TrajectoryFormat::kAuto, DuplicateTimestamps::kKeepAll);
  const Trajectory est = ReadTrajectory(shared / "evo" / "fr2_desk_ORB.txt");
  EvaluationOptions options;
  options.alignment = AlignmentMethod::kSE3;
  ExpectClose(EvaluateTrajectories(gt, est, options).ate_translation_m.rmse, 0.008119, "rmse");
}

TEST(EvaluateTrajectories, ReproducesEvoOnFr1XyzRgbdslam) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const Trajectory gt = ReadTrajectory(shared / "evo" / "freiburg1_xyz-groundtruth.txt");
  const Trajectory est = ReadTrajectory(shared / "evo" / "freiburg1_xyz-rgbdslam.txt");
  const EvaluationResult r = EvaluateTrajectories(gt, est, EvaluationOptions());
  EXPECT_EQ(r.pairs.size(), 785u);
  ExpectClose(r.ate_translation_m.rmse, 0.013470, "rmse");
}

TEST(EvaluateTrajectories, IdenticalTrajectoriesHaveZeroError) {
  const Trajectory gt = Synthetic(50, 1000000000, 50000000);
  for (const auto method : {AlignmentMethod::kNone, AlignmentMethod::kSE3, AlignmentMethod::kSim3,
                            AlignmentMethod::kPosYaw}) {
    EvaluationOptions options;
    options.alignment = method;
    const EvaluationResult r = EvaluateTrajectories(gt, gt, options);
    EXPECT_EQ(r.pairs.size(), 50u);
    EXPECT_LT(r.ate_translation_m.max, 1e-9) << AlignmentMethodName(method);
    EXPECT_LT(r.ate_rotation_deg.max, 1e-5) << AlignmentMethodName(method);
    ASSERT_TRUE(r.rpe.has_value());
    EXPECT_LT(r.rpe->translation_m.max, 1e-9);
    EXPECT_EQ(r.rpe->pairs.size(), 49u);
  }
}

TEST(EvaluateTrajectories, Sim3RecoversScaleAndRotationError) {
  const Trajectory gt = Synthetic(60, 0, 100000000);
  // Estimate = a similarity of the ground truth, its clock 3 ms late.
  const Sim3d est_from_ref(0.5, SO3d::Exp(Eigen::Vector3d(0.2, -0.1, 0.7)),
                           Eigen::Vector3d(3, -2, 1));
  Trajectory est;
  for (const StampedPose& p : gt.poses) {
    est.poses.push_back({p.t_ns + 3000000, SE3d(est_from_ref.so3() * p.pose.so3(),
                                                est_from_ref * p.pose.translation())});
  }
  EvaluationOptions options;
  options.alignment = AlignmentMethod::kSim3;
  const EvaluationResult r = EvaluateTrajectories(gt, est, options);
  EXPECT_EQ(r.pairs.size(), 60u);
  EXPECT_NEAR(r.scale(), 2.0, 1e-9);
  EXPECT_LT(r.ate_translation_m.rmse, 1e-9);
  EXPECT_LT(r.ate_rotation_deg.rmse, 1e-5);
  // Without scale correction the error cannot vanish.
  options.alignment = AlignmentMethod::kSE3;
  EXPECT_GT(EvaluateTrajectories(gt, est, options).ate_translation_m.rmse, 0.1);
  // A known constant rotation error shows up in the rotation ATE.
  Trajectory rotated = gt;
  for (StampedPose& p : rotated.poses) {
    p.pose = SE3d(p.pose.so3() * SO3d::Exp(Eigen::Vector3d(0, 0, 2.0 * M_PI / 180.0)),
                  p.pose.translation());
  }
  options.alignment = AlignmentMethod::kNone;
  const EvaluationResult rot = EvaluateTrajectories(gt, rotated, options);
  EXPECT_NEAR(rot.ate_rotation_deg.rmse, 2.0, 1e-9);
  EXPECT_NEAR(rot.ate_rotation_deg.min, 2.0, 1e-9);
  EXPECT_LT(rot.ate_translation_m.max, 1e-12);
}

TEST(EvaluateTrajectories, NoOverlapNamesBothRanges) {
  Trajectory gt = Synthetic(20, 1000000000, 50000000);
  Trajectory est = Synthetic(20, 5000000000, 50000000);
  est.source = "est.txt";
  try {
    EvaluateTrajectories(gt, est, EvaluationOptions());
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.file(), fs::path("est.txt"));
    EXPECT_NE(what.find("no time overlap"), std::string::npos) << what;
    EXPECT_NE(what.find("1.000..1.950 s"), std::string::npos) << what;
    EXPECT_NE(what.find("5.000..5.950 s"), std::string::npos) << what;
  }
  // A matching offset (evo's --t_offset) brings them together.
  EvaluationOptions shifted;
  shifted.association.offset_s = -4.0;
  EXPECT_EQ(EvaluateTrajectories(gt, est, shifted).pairs.size(), 20u);
}

TEST(EvaluateTrajectories, TooFewPairsAndBadOptionsAreErrors) {
  const Trajectory gt = Synthetic(20, 0, 50000000);
  Trajectory est;
  est.poses = {gt.poses[3], gt.poses[4]};
  EXPECT_THROW(EvaluateTrajectories(gt, est, EvaluationOptions()), InputError);  // se3 needs 3
  EXPECT_THROW(EvaluateTrajectories(gt, Trajectory(), EvaluationOptions()), InputError);
  EvaluationOptions options;
  options.association.max_diff_s = -1.0;
  EXPECT_THROW(EvaluateTrajectories(gt, gt, options), OptionError);
  options = EvaluationOptions();
  options.rpe.delta = 1.5;  // frames must be whole
  EXPECT_THROW(EvaluateTrajectories(gt, gt, options), OptionError);
  options.rpe.delta = 100;  // longer than the trajectory
  EXPECT_THROW(EvaluateTrajectories(gt, gt, options), OptionError);
  options.compute_rpe = false;
  EXPECT_FALSE(EvaluateTrajectories(gt, gt, options).rpe.has_value());
}

TEST(EvaluationJson, HasTheDocumentedKeys) {
  const Trajectory gt = Synthetic(10, 0, 50000000);
  const EvaluationResult r = EvaluateTrajectories(gt, gt, EvaluationOptions());
  const std::string json = EvaluationJson(r);
  for (const char* key : {"\"pairs\": 10", "\"alignment\": \"se3\"", "\"scale\": 1", "\"ate\": {",
                          "\"ate_rot_deg\": {", "\"rpe\": {", "\"rmse\"", "\"mean\"", "\"median\"",
                          "\"std\"", "\"min\"", "\"max\"", "\"sse\"", "\"unit\": \"frames\""}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << " in\n" << json;
  }
  const std::string table = FormatEvaluationTable(r);
  EXPECT_NE(table.find("ATE [m]"), std::string::npos) << table;
  EXPECT_NE(table.find("RPE rot [deg]"), std::string::npos) << table;
}

}  // namespace
}  // namespace pkslam
