// EuRoC folder -> bag (rosbag_euroc.h).
#include <fmt/format.h>

#include <algorithm>
#include <tuple>

#include "core/util/error.h"
#include "core/util/progress.h"
#include "io/dataset_common.h"
#include "io/euroc_dataset.h"
#include "io/ros_messages.h"
#include "io/rosbag_euroc.h"
#include "io/text_rows.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

// A ground-truth row of vicon0 / mocap0 (position and orientation) or leica0 (position).
struct PoseRow {
  std::int64_t t_ns = 0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
};

std::vector<PoseRow> ReadPoseRows(const fs::path& csv, bool with_rotation) {
  std::vector<PoseRow> rows;
  std::optional<std::int64_t> previous;
  const std::size_t fields = with_rotation ? 8 : 4;
  ForEachDataRow(csv, FieldSeparator::kComma, [&](const TextRow& r) {
    RequireFieldCount(r, fields, csv,
                      with_rotation ? "timestamp [ns], p (x, y, z), q (w, x, y, z)"
                                    : "timestamp [ns], p (x, y, z)");
    PoseRow row;
    row.t_ns = Int64Field(r.fields[0], csv, r.line, "timestamp [ns]");
    RequireIncreasing(previous, row.t_ns, csv, r.line);
    previous = row.t_ns;
    for (int k = 0; k < 3; ++k) {
      row.p[k] = DoubleField(r.fields[1 + k], csv, r.line, fmt::format("p[{}]", k));
    }
    if (with_rotation) {
      double q[4];
      for (int k = 0; k < 4; ++k) {
        q[k] = DoubleField(r.fields[4 + k], csv, r.line, fmt::format("q[{}]", k));
      }
      row.q = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);  // stored w, x, y, z: kept as read
    }
    rows.push_back(row);
  });
  return rows;
}

// One message to write: its time, stream (the order among equal times) and row.
struct Event {
  std::int64_t t_ns;
  int stream;
  std::size_t index;
  bool operator<(const Event& o) const {
    return std::tie(t_ns, stream, index) < std::tie(o.t_ns, o.stream, o.index);
  }
};

}  // namespace

StreamCounts ConvertEurocToBag(const fs::path& folder, const fs::path& bag,
                               const EurocToBagOptions& options) {
  options.Check();
  const fs::path mav0 = fs::is_directory(folder / "mav0") ? folder / "mav0" : folder;
  if (!fs::is_regular_file(mav0 / "cam0" / "data.csv")) {
    throw InputError(folder, "not a EuRoC folder (no mav0/cam0/data.csv)");
  }
  // Streams in a fixed order: cam0, cam1, imu0, vicon0, leica0, mocap0.
  std::vector<ImageStream> cameras;
  for (const char* name : {"cam0", "cam1"}) {
    const fs::path dir = mav0 / name;
    if (!fs::is_regular_file(dir / "data.csv")) continue;
    ImageStream stream;
    stream.name = name;
    stream.list_file = dir / "data.csv";
    FillImageStream(ReadEurocImageList(stream.list_file, dir / "data"), 1.5, &stream);
    cameras.push_back(std::move(stream));
  }
  std::vector<ImuSample> imu;
  if (fs::is_regular_file(mav0 / "imu0" / "data.csv")) imu = ReadEurocImu(mav0 / "imu0/data.csv");
  const struct {
    const char* name;
    bool rotation;
    const std::string* topic;
  } ground_truth[] = {{"vicon0", true, &options.topics.vicon},
                      {"leica0", false, &options.topics.leica},
                      {"mocap0", true, &options.topics.mocap}};
  std::vector<std::vector<PoseRow>> poses(3);
  for (int g = 0; g < 3; ++g) {
    const fs::path csv = mav0 / ground_truth[g].name / "data.csv";
    if (fs::is_regular_file(csv)) poses[g] = ReadPoseRows(csv, ground_truth[g].rotation);
  }

  // Stream numbers: cameras 0, 1; IMU 2; ground truth 3 + g.
  std::vector<Event> events;
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    for (std::size_t i = 0; i < cameras[c].images.size(); ++i) {
      events.push_back({cameras[c].images[i].t_ns, static_cast<int>(c), i});
    }
  }
  for (std::size_t i = 0; i < imu.size(); ++i) events.push_back({imu[i].t_ns, 2, i});
  for (int g = 0; g < 3; ++g) {
    for (std::size_t i = 0; i < poses[g].size(); ++i)
      events.push_back({poses[g][i].t_ns, 3 + g, i});
  }
  std::sort(events.begin(), events.end());

  BagWriter writer(bag, options.writer);
  std::map<int, std::uint32_t> connection;
  StreamCounts counts;
  const std::string* camera_topics[] = {&options.topics.cam0, &options.topics.cam1};
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    if (cameras[c].images.empty()) continue;
    connection[static_cast<int>(c)] = writer.AddConnection(*camera_topics[c], RosImageType());
    counts[cameras[c].name] = cameras[c].images.size();
  }
  if (!imu.empty()) {
    connection[2] = writer.AddConnection(options.topics.imu, RosImuType());
    counts["imu0"] = imu.size();
  }
  for (int g = 0; g < 3; ++g) {
    if (poses[g].empty()) continue;
    connection[3 + g] = writer.AddConnection(*ground_truth[g].topic, ground_truth[g].rotation
                                                                         ? RosTransformStampedType()
                                                                         : RosPointStampedType());
    counts[ground_truth[g].name] = poses[g].size();
  }

  Progress progress(fmt::format("writing {}", bag.filename().string()), events.size(),
                    options.quiet);
  for (const Event& e : events) {
    RosHeader header;
    header.seq = static_cast<std::uint32_t>(e.index);
    header.stamp_ns = e.t_ns;
    std::string message;
    if (e.stream < 2) {
      header.frame_id = cameras[e.stream].name;
      message = SerializeRosImage(header, LoadGreyImage(cameras[e.stream].images[e.index].path));
    } else if (e.stream == 2) {
      header.frame_id = "imu0";
      message = SerializeRosImu(header, imu[e.index].gyro, imu[e.index].accel);
    } else {
      const int g = e.stream - 3;
      const PoseRow& row = poses[g][e.index];
      header.frame_id = "world";
      if (ground_truth[g].rotation) {
        message = SerializeRosTransformStamped({header, ground_truth[g].name, row.p, row.q});
      } else {
        message = SerializeRosPointStamped({header, row.p});
      }
    }
    writer.Write(connection.at(e.stream), e.t_ns, message);
    progress.Add();
  }
  writer.Close();
  progress.Finish();
  return counts;
}

}  // namespace pkslam
