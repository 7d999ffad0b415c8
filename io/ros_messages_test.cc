#include "io/ros_messages.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/util/error.h"

namespace pkslam {
namespace {

using ::testing::HasSubstr;

const BagLocation kWhere{"test.bag", std::nullopt};

RosHeader Header(std::int64_t t_ns, std::string frame = "cam0") {
  RosHeader h;
  h.seq = 7;
  h.stamp_ns = t_ns;
  h.frame_id = std::move(frame);
  return h;
}

// A serialised sensor_msgs/Image with any encoding and pixel bytes.
std::string ImageBytes(const std::string& encoding, std::uint32_t width, std::uint32_t height,
                       std::uint32_t step, const std::string& data) {
  std::string out;
  AppendU32(&out, 1);
  AppendTime(&out, 5'000'000'123);
  AppendSized(&out, "cam0");
  AppendU32(&out, height);
  AppendU32(&out, width);
  AppendSized(&out, encoding);
  AppendU8(&out, 0);
  AppendU32(&out, step);
  AppendSized(&out, data);
  return out;
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "no InputError";
}

TEST(RosMessages, Mono8ImageRoundTripsExactly) {
  cv::Mat grey(3, 5, CV_8UC1);
  cv::randu(grey, 0, 256);
  const std::string bytes = SerializeRosImage(Header(1'403'715'273'262'142'976), grey);
  ByteReader in(bytes, kWhere, 100);
  const ByteReader start = in;
  const RosImage image = ParseRosImage(in);
  EXPECT_EQ(image.header.seq, 7u);
  EXPECT_EQ(image.header.stamp_ns, 1'403'715'273'262'142'976);
  EXPECT_EQ(image.header.frame_id, "cam0");
  EXPECT_EQ(image.width, 5u);
  EXPECT_EQ(image.height, 3u);
  EXPECT_EQ(image.encoding, "mono8");
  EXPECT_EQ(image.step, 5u);
  const cv::Mat back = RosImageToGrey(image, start);
  ASSERT_EQ(back.type(), CV_8UC1);
  EXPECT_EQ(cv::countNonZero(back != grey), 0);
}

TEST(RosMessages, ColourImagesBecomeGreyAndPaddedRowsAreRead) {
  cv::Mat rgb(2, 3, CV_8UC3);
  cv::randu(rgb, 0, 256);
  // Rows padded to 12 bytes (step > width * 3).
  std::string data;
  for (int r = 0; r < rgb.rows; ++r) {
    data.append(rgb.ptr<char>(r), 9);
    data.append(3, '\x7f');
  }
  for (const auto& [encoding, code] :
       {std::pair{"rgb8", cv::COLOR_RGB2GRAY}, std::pair{"bgr8", cv::COLOR_BGR2GRAY}}) {
    const std::string bytes = ImageBytes(encoding, 3, 2, 12, data);
    ByteReader in(bytes, kWhere);
    const ByteReader start = in;
    const cv::Mat grey = RosImageToGrey(ParseRosImage(in), start);
    cv::Mat expected;
    cv::cvtColor(rgb, expected, code);
    EXPECT_EQ(cv::countNonZero(grey != expected), 0) << encoding;
  }
}

TEST(RosMessages, UnsupportedEncodingsAndBadSizesAreErrorsAtTheMessage) {
  const auto convert = [](const std::string& bytes) {
    return ErrorOf([&] {
      ByteReader in(bytes, kWhere, 4242);
      const ByteReader start = in;
      RosImageToGrey(ParseRosImage(in), start);
    });
  };
  // mono16 (TUM-VI) is read as its high byte, in either byte order.
  {
    const std::string little("\x34\x12\xff\x80\x00\x01\x10\x00", 8);  // 0x1234 0x80ff ...
    const std::string bytes = ImageBytes("mono16", 2, 2, 4, little);  // outlives the reader
    ByteReader in(bytes, kWhere, 0);
    const ByteReader start = in;
    const cv::Mat grey = RosImageToGrey(ParseRosImage(in), start);
    ASSERT_EQ(grey.type(), CV_8UC1);
    EXPECT_EQ(grey.at<std::uint8_t>(0, 0), 0x12);
    EXPECT_EQ(grey.at<std::uint8_t>(0, 1), 0x80);
    EXPECT_EQ(grey.at<std::uint8_t>(1, 0), 0x01);
    EXPECT_EQ(grey.at<std::uint8_t>(1, 1), 0x00);
  }
  EXPECT_THAT(convert(ImageBytes("mono16", 2, 2, 3, std::string(6, '\0'))),
              HasSubstr("step 3 < 4 bytes per row"));
  EXPECT_THAT(convert(ImageBytes("bayer_rggb8", 2, 2, 2, std::string(4, '\0'))),
              HasSubstr("encoding 'bayer_rggb8' is not supported"));
  EXPECT_THAT(convert(ImageBytes("mono8", 4, 2, 3, std::string(6, '\0'))),
              HasSubstr("step 3 < 4 bytes per row"));
  EXPECT_THAT(convert(ImageBytes("mono8", 4, 2, 4, std::string(7, '\0'))),
              HasSubstr("7 data bytes, not 8"));
  EXPECT_THAT(convert(ImageBytes("mono8", 0, 2, 0, "")), HasSubstr("not plausible"));
}

TEST(RosMessages, ImuRoundTripsExactlyAndSaysItHasNoOrientation) {
  const Eigen::Vector3d gyro(0.1, -1e-17, 3.0000000000000004);
  const Eigen::Vector3d accel(9.80665, -0.25, 1.0 / 3.0);
  const std::string bytes = SerializeRosImu(Header(42, "imu0"), gyro, accel);
  EXPECT_EQ(bytes.size(), 4u + 8 + 4 + 4 + (4 + 9 + 3 + 9 + 3 + 9) * 8);
  ByteReader in(bytes, kWhere);
  const RosImu imu = ParseRosImu(in);
  EXPECT_EQ(imu.header.stamp_ns, 42);
  EXPECT_EQ(imu.angular_velocity, gyro);
  EXPECT_EQ(imu.linear_acceleration, accel);
  // orientation_covariance[0] = -1 (sensor_msgs/Imu: no orientation estimate).
  double first_covariance = 0;
  std::memcpy(&first_covariance, bytes.data() + 4 + 8 + 4 + 4 + 4 * 8, 8);
  EXPECT_EQ(first_covariance, -1.0);
}

TEST(RosMessages, ShortAndLongMessagesAreErrorsNamingTheOffset) {
  const std::string imu =
      SerializeRosImu(Header(42), Eigen::Vector3d::Ones(), -Eigen::Vector3d::Ones());
  const std::string shorter = imu.substr(0, imu.size() - 3);
  EXPECT_THAT(ErrorOf([&] {
                ByteReader in(shorter, kWhere, 1000);
                ParseRosImu(in);
              }),
              HasSubstr("truncated: linear_acceleration_covariance needs 72 bytes, 69 left"));
  const std::string longer = imu + "xy";
  EXPECT_THAT(
      ErrorOf([&] {
        ByteReader in(longer, kWhere, 1000);
        ParseRosImu(in);
      }),
      HasSubstr(fmt::format("byte {}: sensor_msgs/Imu: 2 bytes left over", 1000 + imu.size())));
  // A string length beyond the message.
  std::string bad_frame;
  AppendU32(&bad_frame, 0);
  AppendTime(&bad_frame, 1);
  AppendU32(&bad_frame, 1'000'000);
  EXPECT_THAT(ErrorOf([&] {
                ByteReader in(bad_frame, kWhere);
                ParseRosImu(in);
              }),
              HasSubstr("byte 12: header.frame_id: length 1000000 but only 0 bytes left"));
  // nsecs of 1e9 or more is not a ROS time.
  std::string bad_time;
  AppendU32(&bad_time, 0);
  AppendU32(&bad_time, 1);
  AppendU32(&bad_time, 1'000'000'000);
  EXPECT_THAT(ErrorOf([&] {
                ByteReader in(bad_time, kWhere);
                ParseRosImu(in);
              }),
              HasSubstr("byte 4: header.stamp.nsecs 1000000000 >= 1e9"));
}

TEST(RosMessages, GroundTruthMessagesRoundTripExactly) {
  RosTransformStamped pose;
  pose.header = Header(1'403'715'273'262'142'976, "world");
  pose.child_frame_id = "firefly_sbx";
  pose.translation = Eigen::Vector3d(0.1, 1e300, -2.5);
  pose.rotation = Eigen::Quaterniond(0.5, -0.5, 0.5, 0.7);  // not normalised: kept as it is
  const std::string bytes = SerializeRosTransformStamped(pose);
  ByteReader in(bytes, kWhere);
  const RosTransformStamped back = ParseRosTransformStamped(in);
  EXPECT_EQ(back.header.stamp_ns, pose.header.stamp_ns);
  EXPECT_EQ(back.child_frame_id, "firefly_sbx");
  EXPECT_EQ(back.translation, pose.translation);
  EXPECT_EQ(back.rotation.coeffs(), pose.rotation.coeffs());

  RosPointStamped point{Header(5), Eigen::Vector3d(4.6, -1.8, 0.7)};
  const std::string point_bytes = SerializeRosPointStamped(point);
  ByteReader point_in(point_bytes, kWhere);
  EXPECT_EQ(ParseRosPointStamped(point_in).point, point.point);
}

TEST(RosMessages, TypesCarryTheirMd5AndFullDefinitions) {
  for (const RosMessageType* t :
       {&RosImageType(), &RosImuType(), &RosTransformStampedType(), &RosPointStampedType()}) {
    EXPECT_EQ(t->md5sum.size(), 32u) << t->name;
    EXPECT_THAT(std::string(t->definition), HasSubstr("MSG: std_msgs/Header\n")) << t->name;
  }
  EXPECT_EQ(RosImageType().md5sum, "060021388200f6f0f447d0fcd9c64743");
  EXPECT_EQ(RosImuType().md5sum, "6a62c6daae103f4ff57a132d6f95cec2");
  EXPECT_THAT(std::string(RosImuType().definition), HasSubstr("MSG: geometry_msgs/Quaternion\n"));
  EXPECT_THAT(std::string(RosTransformStampedType().definition),
              HasSubstr("MSG: geometry_msgs/Transform\n"));
}

TEST(RosMessages, SerialisersRefuseWhatAMessageCannotHold) {
  EXPECT_THROW(SerializeRosImage(Header(1), cv::Mat(2, 2, CV_8UC3)), OptionError);
  EXPECT_THROW(SerializeRosImu(Header(-1), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()),
               OptionError);
}

}  // namespace
}  // namespace pkslam
