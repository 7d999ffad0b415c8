// The ROS 1 messages pkslam reads from and writes to bags, in their ROS serialisation
// (little-endian, fields in declaration order, strings and arrays as uint32 length + bytes):
//   std_msgs/Header                 seq uint32, stamp (secs, nsecs uint32), frame_id string
//   sensor_msgs/Image               header, height, width, encoding, is_bigendian uint8, step,
//                                   data uint8[]
//   sensor_msgs/Imu                 header, orientation (x, y, z, w), its covariance [9],
//                                   angular_velocity (x, y, z), [9], linear_acceleration, [9]
//   geometry_msgs/TransformStamped  header, child_frame_id, translation (3), rotation (x,y,z,w)
//   geometry_msgs/PointStamped      header, point (3)
// Each type carries what a bag's connection header must say about it: the name, the md5sum
// ROS computes from the definition, and the definition itself (the field lines of the type and
// of every type it uses, which is what rosbag's Python reader builds its classes from).
// Parsers throw InputError naming the file and byte offset (ByteReader); serialisers throw
// OptionError on values a message cannot hold.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <string>
#include <string_view>

#include "io/rosbag_record.h"

namespace pkslam {

struct RosMessageType {
  std::string_view name;        // "sensor_msgs/Image"
  std::string_view md5sum;      // 32 hex digits
  std::string_view definition;  // the connection header's message_definition
};

const RosMessageType& RosImageType();
const RosMessageType& RosImuType();
const RosMessageType& RosTransformStampedType();
const RosMessageType& RosPointStampedType();

struct RosHeader {
  std::uint32_t seq = 0;
  std::int64_t stamp_ns = 0;
  std::string frame_id;
};

struct RosImage {
  RosHeader header;
  std::uint32_t height = 0;
  std::uint32_t width = 0;
  std::string encoding;  // "mono8", "rgb8", "bgr8", "mono16", ...
  std::uint8_t is_bigendian = 0;
  std::uint32_t step = 0;  // bytes per row
  std::string_view data;   // step * height bytes, a view into the parsed bytes
};

struct RosImu {
  RosHeader header;
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();     // [rad/s]
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();  // [m/s^2]
};

struct RosTransformStamped {
  RosHeader header;
  std::string child_frame_id;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
};

struct RosPointStamped {
  RosHeader header;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
};

// Each parses a whole message: a short one, or bytes left over, is an InputError.
RosImage ParseRosImage(ByteReader& in);
RosImu ParseRosImu(ByteReader& in);
RosTransformStamped ParseRosTransformStamped(ByteReader& in);
RosPointStamped ParseRosPointStamped(ByteReader& in);

// An 8-bit grey image (CV_8UC1, owning its pixels) from mono8 / 8UC1, or rgb8 / bgr8 converted
// to grey. Other encodings (mono16 among them) and a step or data size that does not fit the
// size are InputErrors at `at`'s location.
cv::Mat RosImageToGrey(const RosImage& image, const ByteReader& at);

// Serialised messages. `grey` is CV_8UC1 (written as mono8).
std::string SerializeRosImage(const RosHeader& header, const cv::Mat& grey);
std::string SerializeRosImu(const RosHeader& header, const Eigen::Vector3d& angular_velocity,
                            const Eigen::Vector3d& linear_acceleration);
std::string SerializeRosTransformStamped(const RosTransformStamped& message);
std::string SerializeRosPointStamped(const RosPointStamped& message);

}  // namespace pkslam
