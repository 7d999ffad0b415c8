// Bag -> EuRoC folder (rosbag_euroc.h).
#include <fmt/format.h>

#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <unordered_set>

#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/output_file.h"
#include "core/util/output_guard.h"
#include "core/util/progress.h"
#include "io/ros_messages.h"
#include "io/rosbag_euroc.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

enum class Kind { kImage, kImu, kPose, kPoint };

// One stream of the folder and the bag connections it comes from.
struct Stream {
  std::string name;  // folder under mav0/ and --topics name
  std::string option;
  std::string topic;
  Kind kind = Kind::kImage;
  const RosMessageType* type = nullptr;
  bool required = false;
  std::set<std::uint32_t> connections;
  std::vector<std::pair<std::int64_t, std::string>> rows;  // t_ns, the csv row
  std::unordered_set<std::int64_t> stamps;
  bool warned_zero_stamp = false;
};

std::vector<Stream> WantedStreams(const BagToEurocOptions& o) {
  std::vector<Stream> streams;
  const auto add = [&](const char* name, const char* option, const std::string& topic, Kind kind,
                       const RosMessageType& type, bool required) {
    Stream s;
    s.name = name;
    s.option = option;
    s.topic = topic;
    s.kind = kind;
    s.type = &type;
    s.required = required;
    streams.push_back(std::move(s));
  };
  add("cam0", "cam0", o.topics.cam0, Kind::kImage, RosImageType(), true);
  if (o.write_cam1)
    add("cam1", "cam1", o.topics.cam1, Kind::kImage, RosImageType(), o.require_cam1);
  if (o.write_imu) add("imu0", "imu", o.topics.imu, Kind::kImu, RosImuType(), o.require_imu);
  if (o.write_ground_truth) {
    add("vicon0", "vicon", o.topics.vicon, Kind::kPose, RosTransformStampedType(), false);
    add("leica0", "leica", o.topics.leica, Kind::kPoint, RosPointStampedType(), false);
    add("mocap0", "mocap", o.topics.mocap, Kind::kPose, RosTransformStampedType(), false);
  }
  return streams;
}

// The stream's connections, checked against its message type; none is an error when the
// stream is required.
void FindConnections(const BagReader& bag, Stream* s) {
  for (const BagConnection* c : bag.ConnectionsOn(s->topic)) {
    if (c->type != s->type->name) {
      throw InputError(bag.file(),
                       fmt::format("topic {} holds {} messages, but {} needs {} (pick another "
                                   "topic with --topics {}=TOPIC)",
                                   s->topic, BagText(c->type), s->name, s->type->name, s->option));
    }
    if (c->md5sum != "*" && c->md5sum != s->type->md5sum) {
      throw InputError(
          bag.file(), fmt::format("topic {}: {} with md5sum {}, not ROS's {} (another "
                                  "definition of the message)",
                                  s->topic, BagText(c->type), BagText(c->md5sum), s->type->md5sum));
    }
    if (c->message_count > 0) s->connections.insert(c->id);
  }
  if (s->required && s->connections.empty()) {
    throw InputError(
        bag.file(), fmt::format("no {} messages on topic {} for {} (the bag holds: "
                                "{}; pick topics with --topics {}=TOPIC)",
                                s->type->name, s->topic, s->name, bag.DescribeTopics(), s->option));
  }
}

std::string CsvHeader(Kind kind) {
  switch (kind) {
    case Kind::kImage:
      return "#timestamp [ns],filename\n";
    case Kind::kImu:
      return "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
             "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
    case Kind::kPose:
      return "#timestamp [ns], p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], "
             "q_RS_y [], q_RS_z []\n";
    case Kind::kPoint:
      return "#timestamp [ns], p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m]\n";
  }
  return {};
}

// The message's time: header.stamp, or the record's time when the publisher left it 0.
std::int64_t StampOf(const RosHeader& header, const BagMessage& m, Stream* s) {
  if (header.stamp_ns != 0) return header.stamp_ns;
  if (!s->warned_zero_stamp) {
    PKSLAM_LOG_WARN("{}: topic {} has messages with header.stamp 0; their record time is used",
                    m.location->file.string(), s->topic);
    s->warned_zero_stamp = true;
  }
  return m.time_ns;
}

void AddMessage(const BagMessage& m, const fs::path& dir, const BagToEurocOptions& options,
                Stream* s) {
  ByteReader in = m.Reader();
  const ByteReader start = in;
  std::int64_t t = 0;
  std::string row;
  switch (s->kind) {
    case Kind::kImage: {
      const RosImage image = ParseRosImage(in);
      const cv::Mat grey = RosImageToGrey(image, start);
      t = StampOf(image.header, m, s);
      const std::string name = fmt::format("{}.{}", t, options.image_format);
      if (!s->stamps.count(t)) {
        const fs::path file = dir / "data" / name;
        bool written = false;
        try {
          written = cv::imwrite(
              file.string(), grey,
              {cv::IMWRITE_PNG_COMPRESSION, options.png_compression, cv::IMWRITE_PXM_BINARY, 1});
        } catch (const cv::Exception& e) {
          throw OutputError(file, e.what());
        }
        if (!written) throw OutputError(file, "cv::imwrite failed");
      }
      row = fmt::format("{},{}", t, name);
      break;
    }
    case Kind::kImu: {
      const RosImu imu = ParseRosImu(in);
      t = StampOf(imu.header, m, s);
      const Eigen::Vector3d& w = imu.angular_velocity;
      const Eigen::Vector3d& a = imu.linear_acceleration;
      row = fmt::format("{},{},{},{},{},{},{}", t, w.x(), w.y(), w.z(), a.x(), a.y(), a.z());
      break;
    }
    case Kind::kPose: {
      const RosTransformStamped pose = ParseRosTransformStamped(in);
      t = StampOf(pose.header, m, s);
      const Eigen::Vector3d& p = pose.translation;
      const Eigen::Quaterniond& q = pose.rotation;
      row = fmt::format("{},{},{},{},{},{},{},{}", t, p.x(), p.y(), p.z(), q.w(), q.x(), q.y(),
                        q.z());
      break;
    }
    case Kind::kPoint: {
      const RosPointStamped point = ParseRosPointStamped(in);
      t = StampOf(point.header, m, s);
      row = fmt::format("{},{},{},{}", t, point.point.x(), point.point.y(), point.point.z());
      break;
    }
  }
  if (!s->stamps.insert(t).second) {
    start.Fail(fmt::format("topic {}: a second message stamped {} ns", s->topic, t));
  }
  s->rows.emplace_back(t, std::move(row));
}

}  // namespace

StreamCounts ConvertBagToEuroc(const fs::path& bag_file, const fs::path& out,
                               const BagToEurocOptions& options) {
  options.Check();
  BagReader bag(bag_file, options.reader);
  std::vector<Stream> streams = WantedStreams(options);
  std::set<std::uint32_t> wanted;
  std::map<std::uint32_t, Stream*> by_connection;
  std::uint64_t total = 0;
  for (Stream& s : streams) {
    FindConnections(bag, &s);
    for (const std::uint32_t id : s.connections) {
      wanted.insert(id);
      by_connection[id] = &s;
      for (const BagConnection& c : bag.connections()) total += c.id == id ? c.message_count : 0;
    }
  }
  // The folder is cleared first: it must not hold the bag.
  const fs::path bag_path = fs::weakly_canonical(bag_file);
  const fs::path out_path = fs::weakly_canonical(out);
  const fs::path inside = bag_path.lexically_relative(out_path);
  if (!inside.empty() && *inside.begin() != "..") {
    throw OptionError(fmt::format("--out {} holds the bag {}: write the folder elsewhere",
                                  out.string(), bag_file.string()));
  }
  RemoveOwnedDirectory(out);
  CreateOwnedDirectory(out);
  // A conversion that fails half-way leaves no folder that looks like a dataset.
  struct RemoveUnlessDone {
    const fs::path& dir;
    bool done = false;
    ~RemoveUnlessDone() {
      std::error_code ec;
      if (!done) fs::remove_all(dir, ec);
    }
  } cleanup{out};
  const fs::path mav0 = out / "mav0";
  for (const Stream& s : streams) {
    if (s.connections.empty()) continue;
    fs::create_directories(s.kind == Kind::kImage ? mav0 / s.name / "data" : mav0 / s.name);
  }

  Progress progress(fmt::format("converting {}", bag_file.filename().string()), total,
                    options.quiet);
  bag.ReadMessages(wanted, [&](const BagMessage& m) {
    Stream* s = by_connection.at(m.connection->id);
    AddMessage(m, mav0 / s->name, options, s);
    progress.Add();
  });
  progress.Finish();

  StreamCounts counts;
  for (Stream& s : streams) {
    if (s.connections.empty()) continue;
    std::sort(s.rows.begin(), s.rows.end());
    std::string csv = CsvHeader(s.kind);
    for (const auto& [t, row] : s.rows) csv += row + "\n";
    WriteFileAtomically(mav0 / s.name / "data.csv", csv);
    counts[s.name] = s.rows.size();
  }
  cleanup.done = true;
  return counts;
}

}  // namespace pkslam
