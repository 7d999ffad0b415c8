#include "io/kitti_dataset.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/util/error.h"
#include "io/test_fixtures.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

// KITTI 00-02's published grey calibration (P0, P1).
const char* kCalib =
    "P0: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 0.000000000000e+00 "
    "0.000000000000e+00 7.188560000000e+02 1.852157000000e+02 0.000000000000e+00 "
    "0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 0.000000000000e+00\n"
    "P1: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 -3.861448000000e+02 "
    "0.000000000000e+00 7.188560000000e+02 1.852157000000e+02 0.000000000000e+00 "
    "0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 0.000000000000e+00\n";

class KittiTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir("kitti_test");
    seq_ = dir_ / "sequences" / "00";
    testing::WriteText(seq_ / "times.txt", "0.000000e+00\n1.036594e-01\n2.073185e-01\n");
    testing::WriteText(seq_ / "calib.txt", kCalib);
    for (int i = 0; i < 3; ++i) {
      for (const char* cam : {"image_0", "image_1"}) {
        fs::create_directories(seq_ / cam);
        cv::imwrite((seq_ / cam / fmt::format("{:06d}.png", i)).string(),
                    cv::Mat(376, 1241, CV_8UC1, cv::Scalar(40 * i)));
      }
    }
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_, seq_;
};

TEST_F(KittiTest, ReadsTimesCalibrationAndImages) {
  ASSERT_TRUE(LooksLikeKitti(seq_));
  EXPECT_FALSE(LooksLikeKitti(dir_));
  const KittiSequence k = OpenKittiSequence(seq_);
  ASSERT_EQ(k.left.images.size(), 3u);
  ASSERT_EQ(k.right.images.size(), 3u);
  EXPECT_EQ(k.left.images[1].t_ns, 103659400);
  EXPECT_DOUBLE_EQ(k.fx, 718.856);
  EXPECT_DOUBLE_EQ(k.cy, 185.2157);
  EXPECT_NEAR(k.baseline_m, 386.1448 / 718.856, 1e-12);  // ORB-SLAM3's KITTI00-02 bf / fx
  EXPECT_EQ(k.width, 1241);
  EXPECT_EQ(k.height, 376);
  EXPECT_NEAR(k.rate_hz, 1e9 / 103659400.0, 1e-6);  // the (upper) median interval
  const Settings s = SettingsFromKitti(k);
  EXPECT_TRUE(s.rectified_stereo);
  EXPECT_NEAR(s.Bf(), 386.1448, 1e-9);
  EXPECT_EQ(s.orb.n_features, 2000);
  EXPECT_EQ(s.th_depth, 40);
}

TEST_F(KittiTest, PosesRoundTripAndCountMustMatchTheTimes) {
  const std::vector<std::int64_t> t = ReadKittiTimes(seq_ / "times.txt");
  Trajectory truth;
  for (std::size_t i = 0; i < t.size(); ++i) {
    truth.poses.push_back(
        {t[i], SE3d(SO3d::Exp(Eigen::Vector3d(0, 0.1 * static_cast<double>(i), 0)),
                    Eigen::Vector3d(0.5 * static_cast<double>(i), 0, 2.0))});
  }
  const fs::path poses = dir_ / "poses" / "00.txt";
  fs::create_directories(poses.parent_path());
  WriteKittiPoses(truth, poses);
  EXPECT_EQ(KittiTimesFor(poses), seq_ / "times.txt");
  const Trajectory back = ReadKittiPoses(poses, t);
  ASSERT_EQ(back.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.poses[i].t_ns, t[i]);
    EXPECT_LT((back.poses[i].pose.translation() - truth.poses[i].pose.translation()).norm(), 1e-8);
    EXPECT_LT((back.poses[i].pose.so3().Inverse() * truth.poses[i].pose.so3()).Angle(), 1e-8);
  }
  try {
    ReadKittiPoses(poses, {t[0], t[1]});
    FAIL() << "more poses than times";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("00.txt:3: more poses than the 2 times"),
              std::string::npos)
        << e.what();
  }
}

TEST_F(KittiTest, BadFilesNameFileAndLine) {
  testing::WriteText(seq_ / "times.txt", "0.0\n0.1\n0.05\n");
  EXPECT_THROW(OpenKittiSequence(seq_), InputError);
  testing::WriteText(seq_ / "times.txt", "0.0\n0.1\n0.2\n");
  // P1 with another focal length: not a rectified pair of P0.
  std::string calib = kCalib;
  calib.replace(calib.find("P1: 7.188560000000e+02"), 22, "P1: 7.000000000000e+02");
  testing::WriteText(seq_ / "calib.txt", calib);
  try {
    OpenKittiSequence(seq_);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("calib.txt"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not a rectified pair"), std::string::npos) << e.what();
  }
  testing::WriteText(seq_ / "calib.txt", "P0: 1 2 3\n");
  EXPECT_THROW(OpenKittiSequence(seq_), InputError);
}

// The repository's settings per KITTI calibration group read back with KITTI's published
// numbers (bf = fx * baseline, image size).
TEST(KittiSettingsFiles, EachCalibrationGroupReadsBack) {
  struct Group {
    const char* file;
    double fx, bf;
    int width, height;
  };
  for (const Group& g : {Group{"KITTI00-02.yaml", 718.856, 386.1448, 1241, 376},
                         Group{"KITTI03.yaml", 721.5377, 387.5744, 1242, 375},
                         Group{"KITTI04-12.yaml", 707.0912, 379.8145, 1226, 370}}) {
    const Settings s =
        ReadOrbSlam3Settings(fs::path(PKSLAM_SOURCE_DIR) / "examples/settings/kitti" / g.file);
    EXPECT_TRUE(s.rectified_stereo) << g.file;
    EXPECT_DOUBLE_EQ(s.camera1.fx(), g.fx) << g.file;
    EXPECT_NEAR(s.Bf(), g.bf, 1e-5) << g.file;
    EXPECT_EQ(s.camera1.width(), g.width) << g.file;
    EXPECT_EQ(s.camera1.height(), g.height) << g.file;
    EXPECT_EQ(s.orb.n_features, 2000) << g.file;
  }
}

}  // namespace
}  // namespace pkslam
