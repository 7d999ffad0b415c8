// Reader of ROS 1 bag files, format 2.0 (the format EuRoC and TUM-VI are distributed in).
//
// In-house rather than Debian's librosbag-storage-dev: that package pulls in 59 others (Boost
// filesystem/regex/thread/program-options, ament, pluginlib, class_loader, console_bridge,
// roscpp serialisation, gpgme) for a format of seven record types that is fully documented
// (http://wiki.ros.org/Bags/Format/2.0), and its errors are exceptions without the byte
// offset. This reader is small, depends only on libbz2 and liblz4, checks every length field
// against the bytes that are there, names file and byte offset in every error, and has its own
// fuzz target (fuzz/rosbag_fuzzer.cc). Bags it writes (rosbag_writer.h) are checked with
// Debian's python3-rosbag (tests/rosbag/check_rosbag.py), which also writes the bags this
// reader is tested on.
//
// The bag is read in file order: the header, the index at its end (connections and chunk
// infos: topics, types and message counts are known before any data is read), then every chunk
// with the index data records that follow it, which must list exactly the messages the chunk
// holds. Chunks holding no wanted connection are not decompressed. Only bags written to the
// end are read (an unindexed bag, left by a recording that did not stop cleanly, needs
// `rosbag reindex` first); encrypted bags and format 1.2 are refused. The file is only read.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "io/rosbag_compression.h"
#include "io/rosbag_record.h"

namespace pkslam {

struct BagReaderOptions {
  // Largest uncompressed chunk read: a corrupt size field beyond it is an error before any
  // allocation. rosbag writes chunks of 768 KiB (more when one message is larger).
  std::uint64_t max_chunk_bytes = std::uint64_t{1} << 30;
  // Largest record header (connection headers carry message definitions of a few kB).
  std::uint32_t max_header_bytes = 16u << 20;

  void Check() const;
};

struct BagConnection {
  std::uint32_t id = 0;
  std::string topic;
  std::string type;    // "sensor_msgs/Image"
  std::string md5sum;  // of the type's definition
  std::string message_definition;
  std::uint64_t message_count = 0;  // from the chunk infos
};

struct BagChunkInfo {
  std::uint64_t chunk_pos = 0;  // file offset of the chunk record
  std::int64_t start_ns = 0;
  std::int64_t end_ns = 0;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> counts;  // connection id, messages
};

// One message handed to ReadMessages' callback; `data` is valid during the call only.
struct BagMessage {
  const BagConnection* connection = nullptr;
  std::int64_t time_ns = 0;  // the record's time (when it was recorded), not header.stamp
  std::string_view data;     // the serialised message
  const BagLocation* location = nullptr;
  std::uint64_t offset = 0;  // of data[0] in `location`

  // A reader over `data` whose errors name the message's place in the file.
  ByteReader Reader() const { return ByteReader(data, *location, offset); }
};

class BagReader {
 public:
  // Reads the bag header and the index. InputError (file, byte offset) for a file that is
  // missing, not a bag, truncated, unindexed, encrypted or inconsistent; OptionError for bad
  // options.
  explicit BagReader(std::filesystem::path file, const BagReaderOptions& options = {});

  const std::filesystem::path& file() const { return location_.file; }
  // In id order.
  const std::vector<BagConnection>& connections() const { return connections_; }
  const std::vector<BagChunkInfo>& chunk_infos() const { return chunk_infos_; }
  std::uint64_t message_count() const;
  // The connections publishing on `topic` (a bag may hold several, one per publisher).
  std::vector<const BagConnection*> ConnectionsOn(std::string_view topic) const;
  // "/cam0/image_raw (sensor_msgs/Image, 2912 messages), ...": for error messages.
  std::string DescribeTopics() const;

  // Calls `on_message` for every message of a connection in `wanted` (every message when
  // empty), in file order. InputError on any inconsistency met on the way; what the callback
  // throws passes through.
  void ReadMessages(const std::set<std::uint32_t>& wanted,
                    const std::function<void(const BagMessage&)>& on_message);

 private:
  // A record read from the file: its header fields and where its data is.
  struct Record {
    std::uint64_t at = 0;
    BagFields fields;
    std::uint64_t data_at = 0;
    std::uint32_t data_len = 0;
    std::uint64_t end = 0;
  };

  std::string ReadBytes(std::uint64_t at, std::uint64_t n);
  Record ReadRecord(std::uint64_t at, std::string_view what);
  std::string ReadData(const Record& record);
  // The index data records after the chunk `info` (from `at`); checks them against the chunk's
  // counts and, when it was read, its `entries`. Returns the offset after them.
  std::uint64_t CheckIndexData(
      std::uint64_t at, const BagChunkInfo& info,
      const std::map<std::uint32_t, std::vector<std::pair<std::int64_t, std::uint64_t>>>* entries);
  void ReadIndex(std::uint64_t index_pos, std::uint32_t connection_count,
                 std::uint32_t chunk_count);
  // A connection record: its header `fields` and its `data` (the connection header) at
  // `data_at` of `location`.
  static BagConnection ParseConnection(const BagFields& fields, std::string_view data,
                                       const BagLocation& location, std::uint64_t data_at);
  const BagConnection& ConnectionById(std::uint32_t id, const BagLocation& location,
                                      std::uint64_t at) const;
  // Parses one decompressed chunk, calling back for wanted messages; returns each connection's
  // (time, offset) entries for the check against the index data records.
  std::map<std::uint32_t, std::vector<std::pair<std::int64_t, std::uint64_t>>> ReadChunkRecords(
      std::string_view chunk, const BagLocation& location, const std::set<std::uint32_t>& wanted,
      const std::function<void(const BagMessage&)>& on_message);

  BagReaderOptions options_;
  BagLocation location_;
  std::ifstream in_;
  std::uint64_t file_size_ = 0;
  std::uint64_t first_record_ = 0;  // after the bag header record
  std::uint64_t index_pos_ = 0;
  std::vector<BagConnection> connections_;
  std::vector<BagChunkInfo> chunk_infos_;
};

}  // namespace pkslam
