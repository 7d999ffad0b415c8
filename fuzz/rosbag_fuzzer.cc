// Fuzz target: ROS 1 bags (io/rosbag_reader.h, io/ros_messages.h, io/rosbag_to_euroc.cc). The
// input is one bag file, read message by message with every message parsed as its connection's
// type says (images converted to grey), then converted to a EuRoC folder as `pkslam convert
// --bag` does. Bad input must end in InputError (file and byte offset); anything else is a
// finding. A bag that reads completely must also survive a write/read round trip with
// BagWriter that gives back the same connections and messages.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/util/error.h"
#include "fuzz/fuzz_support.h"
#include "io/ros_messages.h"
#include "io/rosbag_euroc.h"
#include "io/rosbag_reader.h"
#include "io/rosbag_writer.h"

namespace {

using namespace pkslam;

struct Message {
  std::uint32_t connection;
  std::int64_t time_ns;
  std::string data;
  bool operator==(const Message&) const = default;
};

BagReaderOptions SmallChunks() {
  BagReaderOptions options;
  options.max_chunk_bytes = 64u << 20;  // libFuzzer's memory limit is 2 GB
  return options;
}

// Parses `m` as its connection's type; an InputError from a message does not end the bag.
void ParseMessage(const BagMessage& m) {
  try {
    ByteReader in = m.Reader();
    const ByteReader start = in;
    const std::string& type = m.connection->type;
    if (type == RosImageType().name) {
      RosImageToGrey(ParseRosImage(in), start);
    } else if (type == RosImuType().name) {
      ParseRosImu(in);
    } else if (type == RosTransformStampedType().name) {
      ParseRosTransformStamped(in);
    } else if (type == RosPointStampedType().name) {
      ParseRosPointStamped(in);
    }
  } catch (const InputError& e) {
    fuzz::Rejected(e);
  }
}

// Writes what was read as a new bag and reads it back: the same connections and messages.
void RoundTrip(const BagReader& reader, const std::vector<Message>& messages) {
  const auto copy = fuzz::ScratchDir() / "copy.bag";
  std::vector<std::uint32_t> ids;
  {
    BagWriter writer(copy);
    for (const BagConnection& c : reader.connections()) {
      // The writer takes its types' definitions; the copy keeps the name and md5sum read.
      const RosMessageType type{c.type, c.md5sum, c.message_definition};
      ids.push_back(writer.AddConnection(c.topic, type));
    }
    for (const Message& m : messages) {
      std::size_t k = 0;
      while (reader.connections()[k].id != m.connection) ++k;
      writer.Write(ids[k], m.time_ns, m.data);
    }
    writer.Close();
  }
  BagReader back(copy);
  std::vector<Message> read;
  back.ReadMessages({}, [&](const BagMessage& m) {
    read.push_back({m.connection->id, m.time_ns, std::string(m.data)});
  });
  if (back.connections().size() != reader.connections().size()) {
    fuzz::Finding("the round trip changed the number of connections");
  }
  std::vector<Message> expected = messages;
  for (Message& m : expected) {
    std::size_t k = 0;
    while (reader.connections()[k].id != m.connection) ++k;
    m.connection = ids[k];
  }
  if (read != expected) fuzz::Finding("the round trip changed the messages");
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  pkslam::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto bag = fuzz::WriteScratchFile("input.bag", data, size);
  try {
    BagReader reader(bag, SmallChunks());
    std::vector<Message> messages;
    reader.ReadMessages({}, [&](const BagMessage& m) {
      ParseMessage(m);
      messages.push_back({m.connection->id, m.time_ns, std::string(m.data)});
    });
    RoundTrip(reader, messages);
  } catch (const InputError& e) {
    fuzz::Rejected(e);
  }
  try {
    BagToEurocOptions options;
    options.quiet = true;
    options.png_compression = 0;
    options.reader = SmallChunks();
    ConvertBagToEuroc(bag, fuzz::ScratchDir() / "euroc", options);
  } catch (const InputError& e) {
    fuzz::Rejected(e);
  }
  return 0;
}
