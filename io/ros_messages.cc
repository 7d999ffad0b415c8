#include "io/ros_messages.h"

#include <fmt/format.h>

#include <cstring>
#include <opencv2/imgproc.hpp>

#include "core/util/error.h"

namespace pkslam {
namespace {

// The definitions list the field lines of the type, then, after a line of 80 '=', each type
// it uses as "MSG: package/Type" and its field lines (the layout rosbag record writes).
#define PKSLAM_ROS_SEPARATOR \
  "================================================================================\n"
#define PKSLAM_ROS_HEADER "MSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n"
#define PKSLAM_ROS_VECTOR3 "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"
#define PKSLAM_ROS_QUATERNION \
  "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n"

constexpr RosMessageType kImage{
    "sensor_msgs/Image", "060021388200f6f0f447d0fcd9c64743",
    "Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\n"
    "uint32 step\nuint8[] data\n\n" PKSLAM_ROS_SEPARATOR PKSLAM_ROS_HEADER};
constexpr RosMessageType kImu{
    "sensor_msgs/Imu", "6a62c6daae103f4ff57a132d6f95cec2",
    "Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n"
    "geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n"
    "geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n"
    "\n" PKSLAM_ROS_SEPARATOR PKSLAM_ROS_HEADER PKSLAM_ROS_SEPARATOR PKSLAM_ROS_QUATERNION
        PKSLAM_ROS_SEPARATOR PKSLAM_ROS_VECTOR3};
constexpr RosMessageType kTransformStamped{
    "geometry_msgs/TransformStamped", "b5764a33bfeb3588febc2682852579b0",
    "Header header\nstring child_frame_id\nTransform transform\n\n" PKSLAM_ROS_SEPARATOR
        PKSLAM_ROS_HEADER PKSLAM_ROS_SEPARATOR
    "MSG: geometry_msgs/Transform\nVector3 translation\nQuaternion rotation\n" PKSLAM_ROS_SEPARATOR
        PKSLAM_ROS_VECTOR3 PKSLAM_ROS_SEPARATOR PKSLAM_ROS_QUATERNION};
constexpr RosMessageType kPointStamped{
    "geometry_msgs/PointStamped", "c63aecb41bfdfd6b7e1fac37c7cbe7bf",
    "Header header\nPoint point\n\n" PKSLAM_ROS_SEPARATOR PKSLAM_ROS_HEADER PKSLAM_ROS_SEPARATOR
    "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n"};

#undef PKSLAM_ROS_SEPARATOR
#undef PKSLAM_ROS_HEADER
#undef PKSLAM_ROS_VECTOR3
#undef PKSLAM_ROS_QUATERNION

RosHeader ParseHeader(ByteReader& in) {
  RosHeader h;
  h.seq = in.U32("header.seq");
  const std::uint64_t stamp_at = in.offset();
  const std::uint32_t secs = in.U32("header.stamp.secs");
  const std::uint32_t nsecs = in.U32("header.stamp.nsecs");
  const std::optional<std::int64_t> t = RosTimeToNs(secs, nsecs);
  if (!t) in.location().Fail(stamp_at, fmt::format("header.stamp.nsecs {} >= 1e9", nsecs));
  h.stamp_ns = *t;
  h.frame_id = std::string(in.Sized("header.frame_id"));
  return h;
}

void AppendHeader(std::string* out, const RosHeader& h) {
  AppendU32(out, h.seq);
  AppendTime(out, h.stamp_ns);
  AppendSized(out, h.frame_id);
}

Eigen::Vector3d ParseVector3(ByteReader& in, std::string_view what) {
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) v[k] = in.F64(what);
  return v;
}

void AppendVector3(std::string* out, const Eigen::Vector3d& v) {
  for (int k = 0; k < 3; ++k) AppendF64(out, v[k]);
}

void SkipCovariance(ByteReader& in, std::string_view what) { in.Bytes(9 * 8, what); }

void AppendCovariance(std::string* out, double first) {
  AppendF64(out, first);
  for (int k = 1; k < 9; ++k) AppendF64(out, 0.0);
}

}  // namespace

const RosMessageType& RosImageType() { return kImage; }
const RosMessageType& RosImuType() { return kImu; }
const RosMessageType& RosTransformStampedType() { return kTransformStamped; }
const RosMessageType& RosPointStampedType() { return kPointStamped; }

RosImage ParseRosImage(ByteReader& in) {
  RosImage m;
  m.header = ParseHeader(in);
  m.height = in.U32("height");
  m.width = in.U32("width");
  m.encoding = std::string(in.Sized("encoding"));
  m.is_bigendian = in.U8("is_bigendian");
  m.step = in.U32("step");
  m.data = in.Sized("data");
  in.RequireEnd("sensor_msgs/Image");
  return m;
}

cv::Mat RosImageToGrey(const RosImage& m, const ByteReader& at) {
  int channels = 0;
  int to_grey = -1;  // cv::cvtColor code, -1: copy
  if (m.encoding == "mono8" || m.encoding == "8UC1") {
    channels = 1;
  } else if (m.encoding == "rgb8") {
    channels = 3;
    to_grey = cv::COLOR_RGB2GRAY;
  } else if (m.encoding == "bgr8") {
    channels = 3;
    to_grey = cv::COLOR_BGR2GRAY;
  } else if (m.encoding == "mono16" || m.encoding == "16UC1") {
    channels = 2;  // bytes per pixel; to 8 bits below, as OpenCV reads a 16-bit PNG as grey
  } else {
    at.Fail(fmt::format("image encoding '{}' is not supported (mono8, rgb8, bgr8, mono16)",
                        BagText(m.encoding)));
  }
  // 65535 px a side at most: EuRoC is 752x480, TUM-VI 1024x1024; larger is a corrupt header.
  if (m.width == 0 || m.height == 0 || m.width > 65535 || m.height > 65535) {
    at.Fail(fmt::format("image size {}x{} is not plausible", m.width, m.height));
  }
  const std::uint64_t row_bytes = static_cast<std::uint64_t>(m.width) * channels;
  if (m.step < row_bytes) {
    at.Fail(fmt::format("{} image of width {}: step {} < {} bytes per row", m.encoding, m.width,
                        m.step, row_bytes));
  }
  if (m.data.size() != static_cast<std::uint64_t>(m.step) * m.height) {
    at.Fail(fmt::format("{}x{} image with step {}: {} data bytes, not {}", m.width, m.height,
                        m.step, m.data.size(), static_cast<std::uint64_t>(m.step) * m.height));
  }
  const int width = static_cast<int>(m.width);
  const int height = static_cast<int>(m.height);
  if (channels == 2) {
    // TUM-VI's 16-bit images: the high byte of each pixel (the 8-bit image OpenCV's imread
    // gives for the same 16-bit PNG), in the message's byte order.
    cv::Mat grey(height, width, CV_8UC1);
    const int high = m.is_bigendian != 0 ? 0 : 1;
    for (int r = 0; r < height; ++r) {
      const char* row = m.data.data() + static_cast<std::size_t>(r) * m.step;
      auto* out = grey.ptr<std::uint8_t>(r);
      for (int c = 0; c < width; ++c) out[c] = static_cast<std::uint8_t>(row[2 * c + high]);
    }
    return grey;
  }
  // A view of the message's bytes (not modified: OpenCV takes a non-const pointer).
  const cv::Mat view(height, width, channels == 1 ? CV_8UC1 : CV_8UC3,
                     const_cast<char*>(m.data.data()), m.step);
  cv::Mat grey;
  if (to_grey < 0) {
    grey = view.clone();
  } else {
    cv::cvtColor(view, grey, to_grey);
  }
  return grey;
}

std::string SerializeRosImage(const RosHeader& header, const cv::Mat& grey) {
  if (grey.type() != CV_8UC1 || grey.empty()) {
    throw OptionError("a bag image must be a non-empty 8-bit grey image (mono8)");
  }
  std::string out;
  const std::size_t row = static_cast<std::size_t>(grey.cols);
  out.reserve(64 + row * grey.rows);
  AppendHeader(&out, header);
  AppendU32(&out, static_cast<std::uint32_t>(grey.rows));
  AppendU32(&out, static_cast<std::uint32_t>(grey.cols));
  AppendSized(&out, "mono8");
  AppendU8(&out, 0);
  AppendU32(&out, static_cast<std::uint32_t>(row));
  AppendU32(&out, static_cast<std::uint32_t>(row * grey.rows));
  for (int r = 0; r < grey.rows; ++r) out.append(grey.ptr<char>(r), row);
  return out;
}

RosImu ParseRosImu(ByteReader& in) {
  RosImu m;
  m.header = ParseHeader(in);
  in.Bytes(4 * 8, "orientation");
  SkipCovariance(in, "orientation_covariance");
  m.angular_velocity = ParseVector3(in, "angular_velocity");
  SkipCovariance(in, "angular_velocity_covariance");
  m.linear_acceleration = ParseVector3(in, "linear_acceleration");
  SkipCovariance(in, "linear_acceleration_covariance");
  in.RequireEnd("sensor_msgs/Imu");
  return m;
}

std::string SerializeRosImu(const RosHeader& header, const Eigen::Vector3d& angular_velocity,
                            const Eigen::Vector3d& linear_acceleration) {
  std::string out;
  AppendHeader(&out, header);
  // No orientation estimate: sensor_msgs/Imu says so with orientation_covariance[0] = -1.
  for (const double q : {0.0, 0.0, 0.0, 1.0}) AppendF64(&out, q);
  AppendCovariance(&out, -1.0);
  AppendVector3(&out, angular_velocity);
  AppendCovariance(&out, 0.0);  // 0: unknown
  AppendVector3(&out, linear_acceleration);
  AppendCovariance(&out, 0.0);
  return out;
}

RosTransformStamped ParseRosTransformStamped(ByteReader& in) {
  RosTransformStamped m;
  m.header = ParseHeader(in);
  m.child_frame_id = std::string(in.Sized("child_frame_id"));
  m.translation = ParseVector3(in, "transform.translation");
  double q[4];  // x, y, z, w
  for (double& v : q) v = in.F64("transform.rotation");
  m.rotation = Eigen::Quaterniond(q[3], q[0], q[1], q[2]);
  in.RequireEnd("geometry_msgs/TransformStamped");
  return m;
}

std::string SerializeRosTransformStamped(const RosTransformStamped& m) {
  std::string out;
  AppendHeader(&out, m.header);
  AppendSized(&out, m.child_frame_id);
  AppendVector3(&out, m.translation);
  for (const double v : {m.rotation.x(), m.rotation.y(), m.rotation.z(), m.rotation.w()}) {
    AppendF64(&out, v);
  }
  return out;
}

RosPointStamped ParseRosPointStamped(ByteReader& in) {
  RosPointStamped m;
  m.header = ParseHeader(in);
  m.point = ParseVector3(in, "point");
  in.RequireEnd("geometry_msgs/PointStamped");
  return m;
}

std::string SerializeRosPointStamped(const RosPointStamped& m) {
  std::string out;
  AppendHeader(&out, m.header);
  AppendVector3(&out, m.point);
  return out;
}

}  // namespace pkslam
