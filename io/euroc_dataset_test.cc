#include "io/euroc_dataset.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/util/error.h"
#include "io/test_fixtures.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class EurocSynthetic : public ::testing::Test {
 protected:
  void SetUp() override { root_ = testing::MakeTempDir("euroc"); }
  void TearDown() override { fs::remove_all(root_); }
  fs::path Mav0(const std::string& rel) const { return root_ / "mav0" / rel; }

  // Opens the dataset expecting an InputError; returns its message.
  std::string OpenError() const {
    try {
      EurocDataset::Open(root_);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no InputError";
    return "";
  }

  fs::path root_;
  testing::EurocFixture fixture_;
};

TEST_F(EurocSynthetic, ReadsListsImuAndPairs) {
  fixture_.Write(root_);
  const EurocDataset d = EurocDataset::Open(root_);
  EXPECT_EQ(d.cam0().images.size(), 5u);
  ASSERT_TRUE(d.has_cam1());
  EXPECT_EQ(d.stereo_pairs().size(), 5u);
  EXPECT_EQ(d.stereo_pairs()[3].t_ns, fixture_.FrameT(3));
  EXPECT_EQ(d.cam0().images[0].t_ns, 1'403'715'273'262'142'976);  // exact, no double
  EXPECT_EQ(d.imu().size(), 41u);
  EXPECT_TRUE(d.imu_gaps().empty());
  EXPECT_DOUBLE_EQ(d.imu()[3].accel.y(), 3.5);
  EXPECT_DOUBLE_EQ(d.imu()[3].gyro.z(), 0.03);
  EXPECT_FALSE(d.has_ground_truth());
  EXPECT_EQ(d.cam0_sensor().width, 752);
  EXPECT_DOUBLE_EQ(d.cam1_sensor().intrinsics[2], 379.999);
  EXPECT_DOUBLE_EQ(d.imu_sensor().gyroscope_random_walk, 1.9393e-05);
  // Opening the mav0 folder itself works too.
  EXPECT_EQ(EurocDataset::Open(root_ / "mav0").cam0().images.size(), 5u);

  const cv::Mat left = d.LoadCam0(2);
  EXPECT_EQ(left.type(), CV_8UC1);
  EXPECT_EQ(left.at<uint8_t>(0, 0), 20);
  EXPECT_EQ(d.LoadCam1(2).at<uint8_t>(0, 0), 21);

  const auto between = d.ImuBetween(fixture_.FrameT(0), fixture_.FrameT(1));
  ASSERT_EQ(between.size(), 10u);  // t0 < t <= t1
  EXPECT_EQ(between.front().t_ns, fixture_.FrameT(0) + 5'000'000);
  EXPECT_EQ(between.back().t_ns, fixture_.FrameT(1));
}

TEST_F(EurocSynthetic, MissingImagesAreSkippedAndPairsStayExact) {
  fixture_.Write(root_);
  fs::remove(Mav0("cam1/data") / fmt::format("{}.png", fixture_.FrameT(1)));
  fs::remove(Mav0("cam0/data") / fmt::format("{}.png", fixture_.FrameT(3)));
  const EurocDataset d = EurocDataset::Open(root_);
  EXPECT_EQ(d.cam0().listed, 5u);
  EXPECT_EQ(d.cam0().images.size(), 4u);
  ASSERT_EQ(d.cam1().missing.size(), 1u);
  EXPECT_EQ(d.cam1().missing[0].filename(), fmt::format("{}.png", fixture_.FrameT(1)));
  ASSERT_EQ(d.stereo_pairs().size(), 3u);
  for (const StereoPair& p : d.stereo_pairs()) {
    EXPECT_EQ(d.cam0().images[p.left].t_ns, p.t_ns);
    EXPECT_EQ(d.cam1().images[p.right].t_ns, p.t_ns);
  }
  // A skipped frame leaves a 2-period hole in cam0: a frame gap (> 1.5 periods).
  ASSERT_EQ(d.cam0().gaps.size(), 1u);
  EXPECT_EQ(d.cam0().gaps[0].begin_ns, fixture_.FrameT(2));
  EXPECT_NEAR(d.cam0().gaps[0].periods, 2.0, 1e-9);
}

TEST_F(EurocSynthetic, CorruptImageFailsOnLoadNamingTheFile) {
  fixture_.Write(root_);
  const fs::path bad = Mav0("cam0/data") / fmt::format("{}.png", fixture_.FrameT(1));
  testing::WriteText(bad, "not a png");
  const EurocDataset d = EurocDataset::Open(root_);
  EXPECT_NO_THROW(d.LoadCam0(0));
  try {
    d.LoadCam0(1);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), bad);
    EXPECT_THAT(e.what(), HasSubstr("cannot decode"));
  }
  EXPECT_THROW(d.LoadCam0(99), Error);
}

TEST_F(EurocSynthetic, ImuGapsAreReportedNotFatal) {
  fixture_.Write(root_);
  std::string csv = "#timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z\n";
  for (std::int64_t t : {0, 5, 10, 25, 30, 60}) {  // ms: gaps 15 ms (3 periods), 30 ms
    csv += fmt::format("{},0,0,0,0,0,9.81\n", fixture_.t0_ns + t * 1'000'000);
  }
  testing::WriteText(Mav0("imu0/data.csv"), csv);
  const EurocDataset d = EurocDataset::Open(root_);
  ASSERT_EQ(d.imu_gaps().size(), 2u);
  EXPECT_EQ(d.imu_gaps()[0].begin_ns, fixture_.t0_ns + 10'000'000);
  EXPECT_NEAR(d.imu_gaps()[0].periods, 3.0, 1e-9);
  EXPECT_NEAR(d.imu_gaps()[1].periods, 6.0, 1e-9);
}

TEST_F(EurocSynthetic, GroundTruthRows) {
  fixture_.Write(root_);
  testing::WriteText(Mav0("state_groundtruth_estimate0/data.csv"),
                     "#timestamp, p_x, p_y, p_z, q_w, q_x, q_y, q_z, v_x, v_y, v_z, bw_x, bw_y, "
                     "bw_z, ba_x, ba_y, ba_z\n"
                     "1403715274302142976,0.8786,2.1424,0.9472,0.0605,-0.8284,-0.0589,-0.5536,"
                     "0.1,0.2,0.3,-0.002,0.0206,0.0760,-0.0124,0.1033,0.0936\n");
  const EurocDataset d = EurocDataset::Open(root_);
  ASSERT_EQ(d.ground_truth().size(), 1u);
  const EurocGroundTruthState& s = d.ground_truth()[0];
  EXPECT_EQ(s.t_ns, 1403715274302142976);
  EXPECT_NEAR(s.world_from_body.translation().y(), 2.1424, 1e-12);
  const Eigen::Quaterniond q = s.world_from_body.quaternion();
  const double sign = q.w() > 0 ? 1.0 : -1.0;  // stored w first
  EXPECT_NEAR(sign * q.x(), -0.8284 / Eigen::Vector4d(0.0605, -0.8284, -0.0589, -0.5536).norm(),
              1e-9);
  EXPECT_DOUBLE_EQ(s.velocity_world.z(), 0.3);
  EXPECT_DOUBLE_EQ(s.gyro_bias.y(), 0.0206);
  EXPECT_DOUBLE_EQ(s.accel_bias.x(), -0.0124);
}

TEST_F(EurocSynthetic, BadInputsAreInputErrorsWithFileAndLine) {
  fixture_.Write(root_);
  const fs::path csv = Mav0("cam0/data.csv");
  const std::string header = "#timestamp [ns],filename\n";

  testing::WriteText(csv, header + "100,a.png\n100,b.png\n");
  EXPECT_THAT(OpenError(), HasSubstr(csv.string() + ":3: timestamp 100 duplicates"));

  testing::WriteText(csv, header + "200,a.png\n100,b.png\n");
  EXPECT_THAT(OpenError(), HasSubstr(csv.string() + ":3: timestamp 100 is before"));

  testing::WriteText(csv, header + "100,a.png\nhello world\n");
  EXPECT_THAT(OpenError(), HasSubstr(csv.string() + ":3: expected 2 fields"));

  testing::WriteText(csv, header + "1e5,a.png\n");
  EXPECT_THAT(OpenError(), HasSubstr(csv.string() + ":2: timestamp [ns]: '1e5' is not an integer"));

  testing::WriteText(csv, header);
  EXPECT_THAT(OpenError(), HasSubstr(csv.string() + ": no data rows"));

  fixture_.Write(root_);
  const fs::path imu = Mav0("imu0/data.csv");
  testing::WriteText(imu, "#t,w,w,w,a,a,a\n100,0,0,0,0,0,9.8\n105,0,0,0,0,9.8\n");
  EXPECT_THAT(OpenError(), HasSubstr(imu.string() + ":3: expected 7 fields"));
  testing::WriteText(imu, "100,0,0,0,0,0,9.8\n105,0,0,zero,0,0,9.8\n");
  EXPECT_THAT(OpenError(), HasSubstr(imu.string() + ":2: gyro[2]: 'zero' is not a finite number"));
  // Values no MEMS sensor gives: a 1e30 glitch, a gyro in deg/s during a turn (90 "rad/s").
  testing::WriteText(imu, "100,0,0,0,0,0,9.8\n105,0,0,0,1e30,0,9.8\n");
  EXPECT_THAT(OpenError(), HasSubstr(imu.string() + ":2: accelerometer (1e+30, 0, 9.8) beyond"));
  testing::WriteText(imu, "100,0,0,0,0,0,9.8\n105,0,90,0,0,0,9.8\n");
  EXPECT_THAT(OpenError(), HasSubstr(imu.string() + ":2: gyro (0, 90, 0) beyond +-35 rad/s"));

  fixture_.Write(root_);
  const fs::path yaml = Mav0("cam1/sensor.yaml");
  testing::WriteText(yaml, "%YAML:1.0\nT_BS:\n  cols: 4\n  rows: 4\n  data: [1, 0, 0, 0]\n");
  EXPECT_THAT(OpenError(), HasSubstr(yaml.string() + ":2: key 'T_BS': matrix data has 4"));

  fs::remove_all(Mav0("cam0"));
  EXPECT_THAT(OpenError(), HasSubstr("cam0/data.csv: file not found"));
  try {
    EurocDataset::Open(root_ / "nowhere");
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("nowhere: dataset directory not found"));
  }
}

TEST(EurocReal, SharedSliceV101Static) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const EurocDataset d = EurocDataset::Open(shared / "euroc" / "V1_01_easy_static");
  EXPECT_EQ(d.cam0().listed, 95u);
  EXPECT_EQ(d.cam0().images.size(), 95u);
  EXPECT_EQ(d.cam1().listed, 99u);
  EXPECT_EQ(d.cam1().images.size(), 95u);
  EXPECT_EQ(d.cam1().missing.size(), 4u);
  EXPECT_EQ(d.stereo_pairs().size(), 95u);
  EXPECT_EQ(d.imu().size(), 29'120u);
  EXPECT_TRUE(d.imu_gaps().empty());
  EXPECT_TRUE(d.cam0().gaps.empty());
  EXPECT_FALSE(d.has_ground_truth());
  EXPECT_EQ(d.cam0().images.front().t_ns, 1403715273262142976);
  EXPECT_DOUBLE_EQ(d.cam0_sensor().distortion_coefficients[3], 1.76187114e-05);
  EXPECT_DOUBLE_EQ(d.imu_sensor().accelerometer_random_walk, 3.0e-3);
  // Stereo baseline from the two T_BS: 0.110078 m (data README).
  const SE3d right_from_left =
      d.cam1_sensor().body_from_camera.Inverse() * d.cam0_sensor().body_from_camera;
  EXPECT_NEAR(right_from_left.translation().norm(), 0.110078, 1e-6);
  const cv::Mat image = d.LoadCam0(0);
  EXPECT_EQ(image.cols, 752);
  EXPECT_EQ(image.rows, 480);
  EXPECT_EQ(image.type(), CV_8UC1);
}

}  // namespace
}  // namespace pkslam
