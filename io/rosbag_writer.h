// Writer of ROS 1 bag files, format 2.0 (rosbag_reader.h reads them; so do ROS's own tools:
// tests/rosbag/check_rosbag.py reads them with Debian's python3-rosbag). The layout is what
// `rosbag record` writes: the bag header record padded to 4096 bytes, chunks of about
// `chunk_bytes` uncompressed bytes (each connection's connection record in the chunk of its
// first message), each chunk followed by one index data record per connection in it, and at
// the end the index: every connection record (topic, type, md5sum, message_definition), then
// one chunk info record per chunk; the header is rewritten with the index position last.
//
// The bag is written under FILE.partial and renamed to FILE by Close(): a writer destroyed
// without Close() (an exception on the way) leaves no file behind. Not thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <string_view>
#include <vector>

#include "io/ros_messages.h"
#include "io/rosbag_compression.h"

namespace pkslam {

struct BagWriterOptions {
  BagCompression compression = BagCompression::kNone;
  // Uncompressed bytes gathered before a chunk is written (rosbag record's default).
  std::size_t chunk_bytes = 768 * 1024;

  // Throws OptionError unless 0 < chunk_bytes <= 1 GiB.
  void Check() const;
};

class BagWriter {
 public:
  // OutputError when FILE.partial cannot be created.
  explicit BagWriter(std::filesystem::path file, const BagWriterOptions& options = {});
  ~BagWriter();
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  // A new connection (one topic of one type); returns its id for Write().
  std::uint32_t AddConnection(std::string topic, const RosMessageType& type);
  // Appends one serialised message recorded at `t_ns` (0 <= t < 2^32 s: OptionError else).
  void Write(std::uint32_t connection, std::int64_t t_ns, std::string_view message);
  // Writes the last chunk and the index, renames FILE.partial to FILE. OutputError on a
  // failed write.
  void Close();

  const std::filesystem::path& file() const { return file_; }
  std::uint64_t messages() const { return messages_; }

 private:
  struct Connection {
    std::string topic;
    RosMessageType type;
    bool recorded = false;  // its connection record is in a chunk already
  };
  static std::pair<std::string, std::string> ConnectionRecord(std::uint32_t id,
                                                              const Connection& c);
  struct ChunkInfo {
    std::uint64_t chunk_pos = 0;
    std::int64_t start_ns = 0;
    std::int64_t end_ns = 0;
    std::map<std::uint32_t, std::uint32_t> counts;
  };

  void WriteRecord(std::string_view header, std::string_view data);
  void WriteBagHeader(std::uint64_t index_pos);
  void FlushChunk();
  void Require(std::string_view what);

  std::filesystem::path file_;
  std::filesystem::path partial_;
  BagWriterOptions options_;
  std::ofstream out_;
  std::uint64_t position_ = 0;
  bool closed_ = false;
  std::uint64_t messages_ = 0;
  std::vector<Connection> connections_;
  std::vector<ChunkInfo> chunk_infos_;
  // The chunk being gathered: its records, and per connection the (time, offset) of each
  // message in it.
  std::string chunk_;
  ChunkInfo chunk_info_;
  std::map<std::uint32_t, std::vector<std::pair<std::int64_t, std::uint32_t>>> chunk_index_;
};

}  // namespace pkslam
