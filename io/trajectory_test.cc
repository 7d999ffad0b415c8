#include "io/trajectory.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <string>

#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

class TrajectoryFileTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::MakeTempDir("trajectory_test"); }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path Write(const std::string& name, const std::string& content) {
    const fs::path file = dir_ / name;
    std::ofstream(file, std::ios::binary) << content;
    return file;
  }

  // The InputError thrown by reading `content`; fails the test when nothing is thrown.
  InputError ReadError(const std::string& content,
                       TrajectoryFormat format = TrajectoryFormat::kAuto,
                       DuplicateTimestamps duplicates = DuplicateTimestamps::kKeepFirst) {
    const fs::path file = Write("bad.txt", content);
    try {
      ReadTrajectory(file, format, duplicates);
    } catch (const InputError& e) {
      return e;
    }
    ADD_FAILURE() << "no InputError for:\n" << content;
    return InputError(file, "none");
  }

  fs::path dir_;
};

TEST(ParseDecimalAsInt64, SecondsToNanosecondsIsExact) {
  EXPECT_EQ(ParseDecimalAsInt64("1403715524.907143", 9), 1403715524907143000);
  EXPECT_EQ(ParseDecimalAsInt64("1305031102.160407", 9), 1305031102160407000);
  EXPECT_EQ(ParseDecimalAsInt64("1311868163.8697", 9), 1311868163869700000);
  EXPECT_EQ(ParseDecimalAsInt64("+12", 9), 12000000000);
  EXPECT_EQ(ParseDecimalAsInt64("-1.5", 9), -1500000000);
  EXPECT_EQ(ParseDecimalAsInt64(".25", 9), 250000000);
  EXPECT_EQ(ParseDecimalAsInt64("7.", 9), 7000000000);
  EXPECT_EQ(ParseDecimalAsInt64("1.305031102160407e+09", 9), 1305031102160407000);
  EXPECT_EQ(ParseDecimalAsInt64("5E-9", 9), 5);
}

TEST(ParseDecimalAsInt64, RoundsBeyondNanosecondsHalfAwayFromZero) {
  EXPECT_EQ(ParseDecimalAsInt64("0.0000000014", 9), 1);
  EXPECT_EQ(ParseDecimalAsInt64("0.0000000015", 9), 2);
  EXPECT_EQ(ParseDecimalAsInt64("-0.0000000015", 9), -2);
  EXPECT_EQ(ParseDecimalAsInt64("0.00000000049", 9), 0);
  EXPECT_EQ(ParseDecimalAsInt64("1e-30", 9), 0);
  // ORB-SLAM3 writes nanoseconds as doubles with 6 decimals.
  EXPECT_EQ(ParseDecimalAsInt64("1403715274302142976.000000", 0), 1403715274302142976);
  EXPECT_EQ(ParseDecimalAsInt64("99.5", 0), 100);
}

TEST(ParseDecimalAsInt64, RejectsGarbageAndOverflow) {
  for (const char* bad :
       {"", ".", "abc", "1.2.3", "1e", "1e+", "--1", "1 ", "0x10", "nan", "inf", "1,5", "12a"}) {
    EXPECT_FALSE(ParseDecimalAsInt64(bad, 9).has_value()) << bad;
  }
  EXPECT_FALSE(ParseDecimalAsInt64("1e20", 9).has_value());
  EXPECT_FALSE(ParseDecimalAsInt64("9223372036854775808", 0).has_value());
  EXPECT_EQ(ParseDecimalAsInt64("9223372036.854775807", 9),
            std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(ParseDecimalAsInt64("-9223372036.854775808", 9),
            std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(ParseDecimalAsInt64("0e999999", 9), 0);
}

TEST(TrajectoryFormatNames, ParseAndPrint) {
  for (const auto f : {TrajectoryFormat::kAuto, TrajectoryFormat::kTum, TrajectoryFormat::kEuroc,
                       TrajectoryFormat::kOrbSlam3}) {
    EXPECT_EQ(ParseTrajectoryFormat(TrajectoryFormatName(f)), f);
  }
  EXPECT_THROW(ParseTrajectoryFormat("kitti"), OptionError);
}

TEST_F(TrajectoryFileTest, ReadsTumWithCommentsBlankLinesAndCrLf) {
  const fs::path file = Write("t.txt",
                              "# ground truth\r\n"
                              "# timestamp tx ty tz qx qy qz qw\r\n"
                              "\r\n"
                              "1311868163.8697 -0.1357 -1.4217 1.4764 0 0 0 1\r\n"
                              "1311868163.8731\t1 2 3  0 0 1 0\r\n");
  EXPECT_EQ(DetectTrajectoryFormat(file), TrajectoryFormat::kTum);
  const Trajectory traj = ReadTrajectory(file);
  ASSERT_EQ(traj.size(), 2u);
  EXPECT_FALSE(traj.has_extras());
  EXPECT_EQ(traj.source, file);
  EXPECT_EQ(traj.poses[0].t_ns, 1311868163869700000);
  EXPECT_EQ(traj.poses[1].t_ns, 1311868163873100000);
  EXPECT_NEAR(traj.poses[0].pose.translation().y(), -1.4217, 1e-15);
  // qz = 1 is a rotation by pi about z: x maps to -x.
  EXPECT_NEAR((traj.poses[1].pose.so3() * Eigen::Vector3d::UnitX()).x(), -1.0, 1e-12);
}

TEST_F(TrajectoryFileTest, ReadsCommaSeparatedTum) {
  const fs::path file = Write("t.csv", "100.5, 1, 2, 3, 0, 0, 0, 1\n101,4,5,6,0,0,0,1\n");
  EXPECT_EQ(DetectTrajectoryFormat(file), TrajectoryFormat::kTum);
  const Trajectory traj = ReadTrajectory(file);
  ASSERT_EQ(traj.size(), 2u);
  EXPECT_EQ(traj.poses[0].t_ns, 100500000000);
  EXPECT_EQ(traj.poses[1].pose.translation(), Eigen::Vector3d(4, 5, 6));
}

TEST_F(TrajectoryFileTest, ReadsEurocGroundTruthWithExtrasAndWFirstQuaternion) {
  const double h = std::sqrt(0.5);
  const fs::path file = Write(
      "data.csv",
      "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
      "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], "
      "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
      "b_a_RS_S_z [m s^-2]\n" +
          fmt::format("1403715274302142976,0.87,2.14,0.94,{0},0,0,{0},0.1,0.2,0.3,-0.002,0.02,"
                      "0.07,-0.01,0.1,0.08\n",
                      h) +
          "1403715274307142912,0.88,2.15,0.95,1,0,0,0,0,0,0,0,0,0,0,0,0\n");
  EXPECT_EQ(DetectTrajectoryFormat(file), TrajectoryFormat::kEuroc);
  const Trajectory traj = ReadTrajectory(file);
  ASSERT_EQ(traj.size(), 2u);
  ASSERT_TRUE(traj.has_extras());
  EXPECT_EQ(traj.poses[0].t_ns, 1403715274302142976);
  EXPECT_EQ(traj.poses[1].t_ns, 1403715274307142912);
  // q = (w, x, y, z) = (h, 0, 0, h): +90 deg about z.
  EXPECT_NEAR((traj.poses[0].pose.so3() * Eigen::Vector3d::UnitX()).y(), 1.0, 1e-12);
  EXPECT_EQ(traj.extras[0].velocity_world, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(traj.extras[0].gyro_bias, Eigen::Vector3d(-0.002, 0.02, 0.07));
  EXPECT_EQ(traj.extras[0].accel_bias, Eigen::Vector3d(-0.01, 0.1, 0.08));
}

TEST_F(TrajectoryFileTest, DetectsOrbSlam3AndEurocByTimestampMagnitude) {
  const fs::path orb = Write("f_run.txt",
                             "1403715274302142976.000000 0.1 0.2 0.3 0 0 0 1\n"
                             "1403715274352142848.000000 0.1 0.2 0.4 0 0 0 1\n");
  EXPECT_EQ(DetectTrajectoryFormat(orb), TrajectoryFormat::kOrbSlam3);
  const Trajectory traj = ReadTrajectory(orb);
  ASSERT_EQ(traj.size(), 2u);
  EXPECT_EQ(traj.poses[1].t_ns, 1403715274352142848);
  EXPECT_EQ(traj.poses[1].pose.translation().z(), 0.4);

  const fs::path euroc8 = Write("est.csv", "1403715274302142976,1,2,3,1,0,0,0\n");
  EXPECT_EQ(DetectTrajectoryFormat(euroc8), TrajectoryFormat::kEuroc);
  EXPECT_FALSE(ReadTrajectory(euroc8).has_extras());
}

TEST_F(TrajectoryFileTest, ExplicitFormatOverridesDetection) {
  // Nanoseconds from a clock starting at zero look like seconds to the detector.
  const fs::path file = Write("sim.txt", "0 0 0 0 0 0 0 1\n50000000 1 0 0 0 0 0 1\n");
  EXPECT_EQ(ReadTrajectory(file).poses[1].t_ns, 50000000000000000);
  EXPECT_EQ(ReadTrajectory(file, TrajectoryFormat::kOrbSlam3).poses[1].t_ns, 50000000);
  // A TUM file read as EuRoC takes the 5th column as w.
  const fs::path tum = Write("tum.txt", "1 0 0 0 0 0 0 1\n");
  const Trajectory as_euroc = ReadTrajectory(tum, TrajectoryFormat::kEuroc);
  EXPECT_EQ(as_euroc.poses[0].t_ns, 1);
  EXPECT_NEAR(as_euroc.poses[0].pose.quaternion().z(), 1.0, 1e-12);
}

TEST_F(TrajectoryFileTest, NormalisesQuaternions) {
  const Trajectory traj = ReadTrajectory(Write("q.txt", "1 0 0 0 0 0 0 2\n2 0 0 0 0 0 3 4\n"));
  EXPECT_NEAR(traj.poses[0].pose.quaternion().norm(), 1.0, 1e-15);
  EXPECT_NEAR(traj.poses[1].pose.quaternion().z(), 0.6, 1e-15);
  EXPECT_NEAR(traj.poses[1].pose.quaternion().w(), 0.8, 1e-15);
}

TEST_F(TrajectoryFileTest, MissingAndEmptyFilesAreErrors) {
  EXPECT_THROW(ReadTrajectory(dir_ / "nope.txt"), InputError);
  EXPECT_THROW(ReadTrajectory(dir_), InputError);  // a directory
  const InputError empty = ReadError("");
  EXPECT_NE(std::string(empty.what()).find("empty"), std::string::npos) << empty.what();
  const InputError comments = ReadError("# only a header\n\n   \n");
  EXPECT_NE(std::string(comments.what()).find("empty"), std::string::npos) << comments.what();
  EXPECT_THROW(ReadTrajectory(Write("e.txt", ""), TrajectoryFormat::kTum), InputError);
}

TEST_F(TrajectoryFileTest, GarbageLinesNameFileLineAndColumn) {
  const std::string good = "1 0 0 0 0 0 0 1\n";
  {
    const InputError e = ReadError(good + "2 0 zero 0 0 0 0 1\n");
    EXPECT_EQ(e.line(), 2u);
    EXPECT_NE(std::string(e.what()).find("bad.txt:2: column 3: 'zero' is not a number"),
              std::string::npos)
        << e.what();
  }
  {
    const InputError e = ReadError(good + "2 0 0 0 0 0 0 1\n3 0 0 0 0 0 1\n");  // 7 columns
    EXPECT_EQ(e.line(), 3u);
    EXPECT_NE(std::string(e.what()).find("found 7"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ReadError(good + "2 0 0 0 0 0 0 1 9\n").line(), 2u);            // 9 columns
  EXPECT_EQ(ReadError(good + "2,0,,0,0,0,0,1\n").line(), 2u);               // empty csv field
  EXPECT_EQ(ReadError(good + "1.5.2 0 0 0 0 0 0 1\n").line(), 2u);          // bad timestamp
  EXPECT_EQ(ReadError("timestamp x y z qx qy qz qw\n" + good).line(), 1u);  // uncommented header
  // A EuRoC file must keep its column count.
  EXPECT_EQ(ReadError("1403715274302142976,1,2,3,1,0,0,0,0,0,0,0,0,0,0,0,0\n"
                      "1403715274307142912,1,2,3,1,0,0,0\n")
                .line(),
            2u);
}

TEST_F(TrajectoryFileTest, NonFiniteValuesAndZeroQuaternionsAreErrors) {
  const std::string good = "1 0 0 0 0 0 0 1\n";
  const InputError nan = ReadError(good + "2 0 nan 0 0 0 0 1\n");
  EXPECT_EQ(nan.line(), 2u);
  EXPECT_NE(std::string(nan.what()).find("non-finite"), std::string::npos) << nan.what();
  EXPECT_NE(std::string(ReadError(good + "inf 0 0 0 0 0 0 1\n").what()).find("non-finite"),
            std::string::npos);
  EXPECT_EQ(ReadError(good + "2 0 0 0 0 0 0 -inf\n").line(), 2u);
  EXPECT_EQ(ReadError(good + "2 0 0 0 0 0 0 0\n").line(), 2u);
}

TEST_F(TrajectoryFileTest, UnsortedAndDuplicateTimestampsNameTheBreakingLine) {
  const InputError unsorted = ReadError(
      "1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 0 1\n# comment\n1.5 0 0 0 0 0 0 1\n3 0 0 0 0 0 0 1\n");
  EXPECT_EQ(unsorted.line(), 4u);
  EXPECT_NE(std::string(unsorted.what()).find("is before"), std::string::npos) << unsorted.what();
  const std::string repeated =
      "1.0 0 0 0 0 0 0 1\n1.000000000 5 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n2 6 0 0 0 0 0 1\n";
  const InputError duplicate =
      ReadError(repeated, TrajectoryFormat::kAuto, DuplicateTimestamps::kError);
  EXPECT_EQ(duplicate.line(), 2u);
  EXPECT_NE(std::string(duplicate.what()).find("repeats"), std::string::npos) << duplicate.what();
  // By default the first of equal stamps is kept (as evo's nearest-time search would use it).
  const Trajectory kept = ReadTrajectory(Write("dup.txt", repeated));
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept.poses[0].pose.translation().x(), 0.0);
  EXPECT_EQ(kept.poses[1].t_ns, 2000000000);
  EXPECT_EQ(kept.poses[1].pose.translation().x(), 0.0);
  // Going back in time after a repeat is still an error.
  EXPECT_EQ(ReadError("1 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n0.5 0 0 0 0 0 0 1\n").line(), 3u);
}

TEST_F(TrajectoryFileTest, UnknownFormatIsAnError) {
  const InputError e = ReadError("1 2 3 4 5\n");
  EXPECT_EQ(e.line(), 1u);
  EXPECT_NE(std::string(e.what()).find("unknown trajectory format"), std::string::npos) << e.what();
  EXPECT_THROW(DetectTrajectoryFormat(Write("u.txt", "1,2,3,4,5,6,7,8,9,10\n")), InputError);
}

TEST_F(TrajectoryFileTest, TumRoundTripKeepsNanosecondsExactly) {
  Trajectory traj;
  traj.poses.push_back({-1, SE3d()});  // times before 0 are written with a sign
  traj.poses.push_back({1403715274302142976, SE3d(SO3d::Exp(Eigen::Vector3d(0.1, -0.2, 0.3)),
                                                  Eigen::Vector3d(1.25, -2.5, 3.125))});
  traj.poses.push_back({1403715274307142977, SE3d()});
  const fs::path file = dir_ / "out.txt";
  WriteTrajectoryTum(traj, file);
  const Trajectory back = ReadTrajectory(file);
  ASSERT_EQ(back.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.poses[i].t_ns, traj.poses[i].t_ns);
    EXPECT_LT((back.poses[i].pose.translation() - traj.poses[i].pose.translation()).norm(), 1e-9);
    EXPECT_LT((back.poses[i].pose.so3().Inverse() * traj.poses[i].pose.so3()).Angle(), 1e-8);
  }
}

TEST_F(TrajectoryFileTest, EurocAndOrbSlam3RoundTrips) {
  Trajectory traj;
  traj.poses.push_back(
      {1000000001, SE3d(SO3d::Exp(Eigen::Vector3d(0.3, 0.2, 0.1)), Eigen::Vector3d(1, 2, 3))});
  traj.poses.push_back({1403715274307142977, SE3d()});
  traj.extras.resize(2);
  traj.extras[1].velocity_world = Eigen::Vector3d(0.5, 0.25, -1);
  traj.extras[1].accel_bias = Eigen::Vector3d(-0.01, 0.1, 0.08);
  const fs::path euroc = dir_ / "gt.csv";
  WriteTrajectory(traj, euroc, TrajectoryFormat::kEuroc);
  const Trajectory back = ReadTrajectory(euroc);  // the header marks it as EuRoC
  ASSERT_EQ(back.size(), 2u);
  ASSERT_TRUE(back.has_extras());
  EXPECT_EQ(back.poses[0].t_ns, 1000000001);
  EXPECT_EQ(back.poses[1].t_ns, 1403715274307142977);
  EXPECT_LT((back.poses[0].pose.so3().Inverse() * traj.poses[0].pose.so3()).Angle(), 1e-8);
  EXPECT_EQ(back.extras[1].velocity_world, traj.extras[1].velocity_world);
  EXPECT_EQ(back.extras[1].accel_bias, traj.extras[1].accel_bias);

  traj.poses[0].t_ns = 1403715274302142976;
  const fs::path orb = dir_ / "f_out.txt";
  WriteTrajectory(traj, orb, TrajectoryFormat::kOrbSlam3);
  const Trajectory orb_back = ReadTrajectory(orb);
  ASSERT_EQ(orb_back.size(), 2u);
  EXPECT_EQ(orb_back.poses[0].t_ns, 1403715274302142976);
  EXPECT_EQ(orb_back.poses[0].pose.translation(), Eigen::Vector3d(1, 2, 3));
  EXPECT_THROW(WriteTrajectory(traj, orb, TrajectoryFormat::kAuto), OptionError);
}

TEST(TrajectoryMeasures, PathLengthAndDuration) {
  Trajectory traj;
  EXPECT_EQ(PathLengthMeters(traj), 0.0);
  EXPECT_EQ(DurationSeconds(traj), 0.0);
  traj.poses.push_back({1000000000, SE3d(SO3d(), Eigen::Vector3d(0, 0, 0))});
  traj.poses.push_back({1500000000, SE3d(SO3d(), Eigen::Vector3d(3, 4, 0))});
  traj.poses.push_back({3000000000, SE3d(SO3d(), Eigen::Vector3d(3, 4, 2))});
  EXPECT_DOUBLE_EQ(PathLengthMeters(traj), 7.0);
  EXPECT_DOUBLE_EQ(DurationSeconds(traj), 2.0);
}

// The data README lists these path lengths (m) for the real EuRoC ground truth files.
TEST(TrajectoryMeasures, EurocGroundTruthPathLengthsMatchTheDataReadme) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path dir = shared / "euroc" / "groundtruth";
  const std::pair<const char*, double> expected[] = {{"V1_01_easy_original.txt", 58.59},
                                                     {"V1_02_medium.txt", 75.89},
                                                     {"V2_01_easy.txt", 36.50},
                                                     {"MH_01_easy.txt", 80.63},
                                                     {"MH_02_easy.txt", 73.47}};
  for (const auto& [name, length] : expected) {
    const Trajectory traj = ReadTrajectory(dir / name);
    EXPECT_EQ(DetectTrajectoryFormat(dir / name), TrajectoryFormat::kTum) << name;
    EXPECT_NEAR(PathLengthMeters(traj), length, 0.005) << name;  // equal to 2 decimals
  }
  const Trajectory v101 = ReadTrajectory(dir / "V1_01_easy_original.txt");
  EXPECT_NEAR(DurationSeconds(v101), 143.6, 0.05);
}

}  // namespace
}  // namespace pkslam
