// EuRoC folder -> bag -> folder is exact (images after decoding, IMU and ground-truth values,
// timestamps) for every chunk compression; topic options and errors; sensor.yaml files from
// settings read back as the same calibration.
#include "io/rosbag_euroc.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "core/util/error.h"
#include "io/euroc_dataset.h"
#include "io/ros_messages.h"
#include "io/rosbag_euroc_sensors.h"
#include "io/settings.h"
#include "io/settings_euroc.h"
#include "io/test_fixtures.h"
#include "io/text_rows.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A EuRoC folder: the fixture's cameras (noise images) and IMU, and vicon0 / leica0 rows.
fs::path MakeFolder(const fs::path& root) {
  testing::EurocFixture fixture;
  fixture.frames = 12;
  fixture.Write(root);
  cv::RNG rng(7);
  for (const char* cam : {"cam0", "cam1"}) {
    for (const auto& e : fs::directory_iterator(root / "mav0" / cam / "data")) {
      cv::Mat noise(48, 64, CV_8UC1);
      rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
      cv::imwrite(e.path().string(), noise);
    }
  }
  std::string vicon =
      "#timestamp [ns], p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], "
      "q_RS_x [], q_RS_y [], q_RS_z []\n";
  std::string leica = "#timestamp [ns], p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m]\n";
  for (int i = 0; i < 30; ++i) {
    const std::int64_t t = fixture.t0_ns + 10'000'000LL * i + 3;
    vicon += fmt::format("{},{},0.1,-2.5e-7,0.70710678118654757,0,0.70710678118654746,{}\n", t,
                         0.1 * i, 1e-9 * i);
    leica += fmt::format("{},{},{},0.3\n", t + 1, 4.6 + 0.01 * i, -1.8);
  }
  testing::WriteText(root / "mav0" / "vicon0" / "data.csv", vicon);
  testing::WriteText(root / "mav0" / "leica0" / "data.csv", leica);
  return root;
}

EurocToBagOptions QuietToBag() {
  EurocToBagOptions options;
  options.quiet = true;
  return options;
}

BagToEurocOptions QuietToFolder() {
  BagToEurocOptions options;
  options.quiet = true;
  return options;
}

// Every data row of a csv as (t_ns, values); values parsed as doubles.
std::vector<std::pair<std::int64_t, std::vector<double>>> Rows(const fs::path& csv) {
  std::vector<std::pair<std::int64_t, std::vector<double>>> rows;
  ForEachDataRow(csv, FieldSeparator::kComma, [&](const TextRow& r) {
    std::vector<double> values;
    for (std::size_t k = 1; k < r.fields.size(); ++k) values.push_back(*ParseDouble(r.fields[k]));
    rows.emplace_back(*ParseInt64(r.fields[0]), values);
  });
  return rows;
}

void ExpectSameImages(const fs::path& a, const fs::path& b) {
  const auto list_a = ReadEurocImageList(a / "data.csv", a / "data");
  const auto list_b = ReadEurocImageList(b / "data.csv", b / "data");
  ASSERT_EQ(list_a.size(), list_b.size());
  for (std::size_t i = 0; i < list_a.size(); ++i) {
    EXPECT_EQ(list_a[i].t_ns, list_b[i].t_ns);
    const cv::Mat image_a = cv::imread(list_a[i].path.string(), cv::IMREAD_UNCHANGED);
    const cv::Mat image_b = cv::imread(list_b[i].path.string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(image_b.type(), CV_8UC1);
    ASSERT_EQ(image_a.size(), image_b.size());
    EXPECT_EQ(cv::countNonZero(image_a != image_b), 0) << list_b[i].path;
  }
}

class FolderBagFolder : public ::testing::TestWithParam<BagCompression> {};

TEST_P(FolderBagFolder, IsExact) {
  const fs::path dir = testing::MakeTempDir("rosbag_euroc");
  const fs::path folder = MakeFolder(dir / "seq");
  EurocToBagOptions to_bag = QuietToBag();
  to_bag.writer.compression = GetParam();
  const StreamCounts written = ConvertEurocToBag(folder, dir / "seq.bag", to_bag);
  EXPECT_EQ(
      written,
      (StreamCounts{{"cam0", 12}, {"cam1", 12}, {"imu0", 111}, {"vicon0", 30}, {"leica0", 30}}));
  const StreamCounts read = ConvertBagToEuroc(dir / "seq.bag", dir / "back", QuietToFolder());
  EXPECT_EQ(read, written);
  const fs::path a = folder / "mav0";
  const fs::path b = dir / "back" / "mav0";
  ExpectSameImages(a / "cam0", b / "cam0");
  ExpectSameImages(a / "cam1", b / "cam1");
  for (const char* stream : {"imu0", "vicon0", "leica0"}) {
    EXPECT_EQ(Rows(a / stream / "data.csv"), Rows(b / stream / "data.csv")) << stream;
  }
  EXPECT_FALSE(fs::exists(b / "mocap0"));
  // The same readers the run uses accept the result.
  EXPECT_EQ(ReadEurocImu(b / "imu0" / "data.csv").size(), 111u);
}

INSTANTIATE_TEST_SUITE_P(Compressions, FolderBagFolder,
                         ::testing::Values(BagCompression::kNone, BagCompression::kBz2,
                                           BagCompression::kLz4),
                         [](const auto& info) {
                           return std::string(BagCompressionName(info.param));
                         });

TEST(RosbagEuroc, TopicsAreOverriddenByName) {
  const BagTopics topics = ParseBagTopics("cam0=/left/image, imu=/imu/data");
  EXPECT_EQ(topics.cam0, "/left/image");
  EXPECT_EQ(topics.imu, "/imu/data");
  EXPECT_EQ(topics.cam1, "/cam1/image_raw");
  EXPECT_EQ(ParseBagTopics("").leica, "/leica/position");
  EXPECT_THAT([] { ParseBagTopics("cam2=/x"); },
              ::testing::ThrowsMessage<OptionError>(HasSubstr("unknown stream 'cam2'")));
  EXPECT_THROW(ParseBagTopics("cam0"), OptionError);
  EXPECT_THROW(ParseBagTopics("cam0=image"), OptionError);
  EXPECT_THAT([] { ParseBagTopics("cam1=/cam0/image_raw"); },
              ::testing::ThrowsMessage<OptionError>(HasSubstr("cam0 and cam1 are both")));
}

TEST(RosbagEuroc, MissingTopicsAndWrongTypesNameTheBagAndItsTopics) {
  const fs::path dir = testing::MakeTempDir("rosbag_euroc_errors");
  ConvertEurocToBag(MakeFolder(dir / "seq"), dir / "seq.bag", QuietToBag());
  BagToEurocOptions options = QuietToFolder();
  options.topics = ParseBagTopics("cam0=/left");
  EXPECT_THAT([&] { ConvertBagToEuroc(dir / "seq.bag", dir / "a", options); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("seq.bag: no sensor_msgs/Image messages on topic /left for cam0 (the "
                            "bag holds: /cam0/image_raw (sensor_msgs/Image, 12 messages)")));
  options.topics = ParseBagTopics("cam0=/imu0,imu=/cam0/image_raw");
  EXPECT_THAT([&] { ConvertBagToEuroc(dir / "seq.bag", dir / "a", options); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("topic /imu0 holds sensor_msgs/Imu messages, but cam0 needs "
                            "sensor_msgs/Image")));
  // A stereo-inertial bag without its IMU.
  testing::EurocFixture visual;
  visual.with_imu = false;
  visual.Write(dir / "visual");
  ConvertEurocToBag(dir / "visual", dir / "visual.bag", QuietToBag());
  options = QuietToFolder();
  options.require_imu = true;
  EXPECT_THAT([&] { ConvertBagToEuroc(dir / "visual.bag", dir / "b", options); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("no sensor_msgs/Imu messages on "
                                                             "topic /imu0 for imu0")));
  // A folder pkslam did not make is not overwritten.
  testing::WriteText(dir / "mine" / "notes.txt", "keep");
  EXPECT_THROW(ConvertBagToEuroc(dir / "seq.bag", dir / "mine", QuietToFolder()), OptionError);
  EXPECT_TRUE(fs::exists(dir / "mine" / "notes.txt"));
  // Nor one that holds the bag.
  ConvertBagToEuroc(dir / "seq.bag", dir / "owned", QuietToFolder());
  fs::copy_file(dir / "seq.bag", dir / "owned" / "inside.bag");
  EXPECT_THAT(
      [&] { ConvertBagToEuroc(dir / "owned" / "inside.bag", dir / "owned", QuietToFolder()); },
      ::testing::ThrowsMessage<OptionError>(HasSubstr("holds the bag")));
  EXPECT_TRUE(fs::exists(dir / "owned" / "inside.bag"));
}

TEST(RosbagEuroc, RowsAreSortedByStampAndRepeatedStampsRefused) {
  const fs::path dir = testing::MakeTempDir("rosbag_euroc_order");
  const auto imu_at = [](std::int64_t stamp) {
    RosHeader h;
    h.stamp_ns = stamp;
    return SerializeRosImu(h, Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(stamp, 0, 9.8));
  };
  const auto image_at = [](std::int64_t stamp) {
    RosHeader h;
    h.stamp_ns = stamp;
    return SerializeRosImage(h, cv::Mat(4, 6, CV_8UC1, cv::Scalar(stamp % 200)));
  };
  {
    BagWriter writer(dir / "order.bag");
    const std::uint32_t cam = writer.AddConnection("/cam0/image_raw", RosImageType());
    const std::uint32_t imu = writer.AddConnection("/imu0", RosImuType());
    // Recorded in another order than stamped; one message without a stamp (its record time).
    writer.Write(cam, 1000, image_at(30));
    writer.Write(cam, 1001, image_at(10));
    writer.Write(imu, 1002, imu_at(25));
    writer.Write(imu, 1003, imu_at(5));
    writer.Write(imu, 1004, imu_at(0));
    writer.Close();
  }
  ConvertBagToEuroc(dir / "order.bag", dir / "order", QuietToFolder());
  const auto cam0 = Rows(dir / "order/mav0/cam0/data.csv");
  ASSERT_EQ(cam0.size(), 2u);
  EXPECT_EQ(cam0[0].first, 10);
  EXPECT_EQ(cam0[1].first, 30);
  const auto imu = Rows(dir / "order/mav0/imu0/data.csv");
  ASSERT_EQ(imu.size(), 3u);
  EXPECT_EQ(imu[0].first, 5);
  EXPECT_EQ(imu[1].first, 25);
  EXPECT_EQ(imu[2].first, 1004);  // header.stamp 0: the record time
  EXPECT_EQ(imu[1].second[3], 25.0);

  {
    BagWriter writer(dir / "twice.bag");
    const std::uint32_t cam = writer.AddConnection("/cam0/image_raw", RosImageType());
    const std::uint32_t imu = writer.AddConnection("/imu0", RosImuType());
    writer.Write(cam, 1000, image_at(30));
    writer.Write(imu, 1001, imu_at(7));
    writer.Write(imu, 1002, imu_at(7));
    writer.Close();
  }
  EXPECT_THAT([&] { ConvertBagToEuroc(dir / "twice.bag", dir / "twice", QuietToFolder()); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("topic /imu0: a second message "
                                                             "stamped 7 ns")));
  EXPECT_FALSE(fs::exists(dir / "twice"));  // a failed conversion leaves no folder
}

TEST(RosbagEuroc, SensorFilesFromSettingsReadBackAsTheSameCalibration) {
  const fs::path dir = testing::MakeTempDir("rosbag_euroc_sensors");
  const fs::path folder = MakeFolder(dir / "seq");
  ConvertEurocToBag(folder, dir / "seq.bag", QuietToBag());
  ConvertBagToEuroc(dir / "seq.bag", dir / "back", QuietToFolder());
  const fs::path settings_file =
      fs::path(PKSLAM_SOURCE_DIR) / "io/testdata/euroc_stereo_inertial.yaml";
  const Settings settings = ReadOrbSlam3Settings(settings_file);
  WriteEurocSensorFiles(settings, dir / "back" / "mav0", settings_file.string());
  const EurocDataset dataset = EurocDataset::Open(dir / "back");
  EXPECT_EQ(dataset.cam0().images.size(), 12u);
  EXPECT_EQ(dataset.stereo_pairs().size(), 12u);
  EXPECT_EQ(dataset.imu().size(), 111u);
  const Settings back = SettingsFromEuroc(dataset);
  EXPECT_TRUE(SameCalibration(back.camera1, settings.camera1));
  ASSERT_TRUE(back.camera2 && settings.camera2);
  EXPECT_TRUE(SameCalibration(*back.camera2, *settings.camera2));
  EXPECT_LT((back.right_from_left->Matrix() - settings.right_from_left->Matrix()).norm(), 1e-12);
  EXPECT_LT((back.body_from_cam0->Matrix() - settings.body_from_cam0->Matrix()).norm(), 1e-12);
  EXPECT_EQ(back.fps, settings.fps);
  EXPECT_EQ(back.imu->gyro_noise_density, settings.imu->gyro_noise_density);
  EXPECT_EQ(back.imu->rate_hz, settings.imu->rate_hz);

  // Monocular settings cannot describe cam1.
  Settings mono = settings;
  mono.camera2.reset();
  mono.right_from_left.reset();
  EXPECT_THAT([&] { WriteEurocSensorFiles(mono, dir / "back" / "mav0", "mono.yaml"); },
              ::testing::ThrowsMessage<OptionError>(HasSubstr("mono.yaml describes one camera")));
}

}  // namespace
}  // namespace pkslam
