// BagReader's chunk contents (connection and message data records) and the index data records
// that follow each chunk (rosbag_reader.h).
#include <fmt/format.h>

#include <algorithm>

#include "core/util/error.h"
#include "io/rosbag_reader.h"

namespace pkslam {

using ChunkEntries = std::map<std::uint32_t, std::vector<std::pair<std::int64_t, std::uint64_t>>>;

ChunkEntries BagReader::ReadChunkRecords(std::string_view chunk, const BagLocation& location,
                                         const std::set<std::uint32_t>& wanted,
                                         const std::function<void(const BagMessage&)>& on_message) {
  ChunkEntries entries;
  ByteReader in(chunk, location);
  while (in.remaining() > 0) {
    const std::uint64_t at = in.offset();
    const std::uint32_t header_len = in.U32("record header length");
    const std::uint64_t header_at = in.offset();
    const BagFields fields =
        BagFields::Parse(in.Bytes(header_len, "record header"), location, header_at);
    const std::uint64_t data_at = in.offset() + 4;
    const std::string_view data = in.Sized("record data");
    const std::uint8_t op = fields.U8("op");
    if (op == static_cast<std::uint8_t>(BagOp::kConnection)) {
      // Repeats a connection of the index: it must be the same one.
      const BagConnection c = ParseConnection(fields, data, location, data_at);
      const BagConnection& known = ConnectionById(c.id, location, at);
      if (c.topic != known.topic || c.type != known.type || c.md5sum != known.md5sum) {
        location.Fail(
            at, fmt::format("connection {} is {} ({}, md5sum {}) here but {} ({}, "
                            "md5sum {}) in the index",
                            c.id, BagText(c.topic), BagText(c.type), BagText(c.md5sum),
                            BagText(known.topic), BagText(known.type), BagText(known.md5sum)));
      }
    } else if (op == static_cast<std::uint8_t>(BagOp::kMessageData)) {
      const std::uint32_t id = fields.U32("conn");
      const std::int64_t time_ns = fields.TimeNs("time");
      const BagConnection& connection = ConnectionById(id, location, at);
      entries[id].emplace_back(time_ns, at);
      if (wanted.empty() || wanted.count(id) > 0) {
        BagMessage m;
        m.connection = &connection;
        m.time_ns = time_ns;
        m.data = data;
        m.location = &location;
        m.offset = data_at;
        on_message(m);
      }
    } else {
      location.Fail(at, fmt::format("{} record inside a chunk (only connection and message data "
                                    "records belong there)",
                                    BagOpName(op)));
    }
  }
  return entries;
}

std::uint64_t BagReader::CheckIndexData(std::uint64_t at, const BagChunkInfo& info,
                                        const ChunkEntries* entries) {
  std::set<std::uint32_t> seen;
  while (at < index_pos_) {
    const Record r = ReadRecord(at, "an index data record");
    if (r.fields.U8("op") != static_cast<std::uint8_t>(BagOp::kIndexData)) break;  // next chunk
    if (const std::uint32_t version = r.fields.U32("ver"); version != 1) {
      location_.Fail(at, fmt::format("index data version {} (only 1 is known)", version));
    }
    const std::uint32_t id = r.fields.U32("conn");
    const std::uint32_t count = r.fields.U32("count");
    if (std::uint64_t{count} * 12 != r.data_len) {
      location_.Fail(at, fmt::format("index data of {} messages holds {} bytes, not {}", count,
                                     r.data_len, std::uint64_t{count} * 12));
    }
    if (!seen.insert(id).second) {
      location_.Fail(at, fmt::format("a second index data record for connection {}", id));
    }
    const auto listed = std::find_if(info.counts.begin(), info.counts.end(),
                                     [&](const auto& c) { return c.first == id; });
    if (listed == info.counts.end() || listed->second != count) {
      location_.Fail(at, fmt::format("index data: {} messages of connection {}, the chunk info "
                                     "says {}",
                                     count, id, listed == info.counts.end() ? 0 : listed->second));
    }
    if (entries != nullptr) {
      // rosbag's C++ writer lists a chunk's entries by time, its Python writer in file order:
      // compared as sets.
      const std::string data = ReadData(r);
      ByteReader in(data, location_, r.data_at);
      std::vector<std::pair<std::int64_t, std::uint64_t>> listed_entries;
      for (std::uint32_t k = 0; k < count; ++k) {
        const std::uint64_t entry_at = in.offset();
        const std::uint32_t secs = in.U32("index time");
        const std::uint32_t nsecs = in.U32("index time");
        const std::optional<std::int64_t> t = RosTimeToNs(secs, nsecs);
        if (!t) location_.Fail(entry_at, fmt::format("index time: nsecs {} >= 1e9", nsecs));
        listed_entries.emplace_back(*t, in.U32("index offset"));
      }
      const auto found = entries->find(id);
      std::vector<std::pair<std::int64_t, std::uint64_t>> held;
      if (found != entries->end()) held = found->second;
      std::sort(held.begin(), held.end());
      std::sort(listed_entries.begin(), listed_entries.end());
      if (held != listed_entries) {
        location_.Fail(at, fmt::format("index data of connection {} does not match the message "
                                       "records of the chunk at byte {}",
                                       id, info.chunk_pos));
      }
    }
    at = r.end;
  }
  if (seen.size() != info.counts.size()) {
    location_.Fail(at, fmt::format("the chunk at byte {} has index data for {} connections, its "
                                   "chunk info lists {}",
                                   info.chunk_pos, seen.size(), info.counts.size()));
  }
  if (entries != nullptr) {
    for (const auto& [id, list] : *entries) {
      if (seen.count(id) == 0) {
        location_.Fail(at, fmt::format("the chunk at byte {} holds messages of connection {} "
                                       "that no index data record lists",
                                       info.chunk_pos, id));
      }
    }
  }
  return at;
}

}  // namespace pkslam
