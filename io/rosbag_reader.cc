#include "io/rosbag_reader.h"

#include <fmt/format.h>

#include <algorithm>

#include "core/util/error.h"

namespace pkslam {

namespace fs = std::filesystem;

using ChunkEntries = std::map<std::uint32_t, std::vector<std::pair<std::int64_t, std::uint64_t>>>;

namespace {

void RequireOp(const BagFields& fields, BagOp op, const BagLocation& location, std::uint64_t at,
               std::string_view expected) {
  const std::uint8_t found = fields.U8("op");
  if (found != static_cast<std::uint8_t>(op)) {
    location.Fail(at, fmt::format("{} record where {} was expected", BagOpName(found), expected));
  }
}

}  // namespace

void BagReaderOptions::Check() const {
  PKSLAM_CHECK_OPTION(max_chunk_bytes > 0, "max_chunk_bytes", "{}", max_chunk_bytes);
  PKSLAM_CHECK_OPTION(max_header_bytes > 0, "max_header_bytes", "{}", max_header_bytes);
}

BagReader::BagReader(fs::path file, const BagReaderOptions& options) : options_(options) {
  options_.Check();
  location_.file = std::move(file);
  std::error_code ec;
  if (fs::is_directory(location_.file, ec)) {
    throw InputError(location_.file, "is a directory, not a bag file");
  }
  if (!fs::exists(location_.file, ec)) throw InputError(location_.file, "file not found");
  in_.open(location_.file, std::ios::binary);
  file_size_ = fs::file_size(location_.file, ec);
  if (!in_ || ec) throw InputError(location_.file, "cannot be opened for reading");

  const std::string magic = ReadBytes(0, std::min<std::uint64_t>(file_size_, kBagMagic.size()));
  if (file_size_ == 0) location_.Fail(0, "empty file, not a ROS bag");
  if (magic != kBagMagic && kBagMagic.starts_with(magic)) {
    location_.Fail(0, fmt::format("truncated: the file ends at byte {}, inside the '#ROSBAG "
                                  "V2.0' line",
                                  file_size_));
  }
  if (magic.starts_with("#ROSBAG V") && magic != kBagMagic) {
    location_.Fail(0, fmt::format("bag format {} is not supported (only 2.0)",
                                  BagText(magic.substr(9, magic.find('\n', 9) - 9))));
  }
  if (magic != kBagMagic) location_.Fail(0, "not a ROS bag (no '#ROSBAG V2.0' line)");
  const Record header = ReadRecord(kBagMagic.size(), "the bag header");
  RequireOp(header.fields, BagOp::kBagHeader, location_, header.at, "the bag header");
  if (header.fields.Find("encryptor"))
    location_.Fail(header.at, "encrypted bags are not supported");
  index_pos_ = header.fields.U64("index_pos");
  const std::uint32_t connection_count = header.fields.U32("conn_count");
  const std::uint32_t chunk_count = header.fields.U32("chunk_count");
  first_record_ = header.end;
  if (index_pos_ == 0) {
    location_.Fail(header.at,
                   "the bag has no index (its recording did not end cleanly): run "
                   "`rosbag reindex` on a copy first");
  }
  if (index_pos_ < first_record_ || index_pos_ > file_size_) {
    location_.Fail(header.at, fmt::format("the index is at byte {}, but the file ends at byte {}"
                                          "{}",
                                          index_pos_, file_size_,
                                          index_pos_ > file_size_ ? " (truncated)" : ""));
  }
  ReadIndex(index_pos_, connection_count, chunk_count);
}

std::string BagReader::ReadBytes(std::uint64_t at, std::uint64_t n) {
  std::string bytes(n, '\0');
  in_.clear();
  in_.seekg(static_cast<std::streamoff>(at));
  in_.read(bytes.data(), static_cast<std::streamsize>(n));
  if (!in_) location_.Fail(at, fmt::format("read error ({} bytes)", n));
  return bytes;
}

BagReader::Record BagReader::ReadRecord(std::uint64_t at, std::string_view what) {
  if (at > file_size_ || file_size_ - at < 4) {
    location_.Fail(at, fmt::format("truncated: the file ends at byte {} where {} should begin",
                                   file_size_, what));
  }
  const std::string length = ReadBytes(at, 4);
  const std::uint32_t header_len = ByteReader(length, location_, at).U32("header length");
  if (header_len > options_.max_header_bytes) {
    location_.Fail(at,
                   fmt::format("record header of {} bytes (corrupt length field?)", header_len));
  }
  if (file_size_ - at - 4 < std::uint64_t{header_len} + 4) {
    location_.Fail(at, fmt::format("truncated: {} has a {} byte header, the file ends at byte {}",
                                   what, header_len, file_size_));
  }
  Record r;
  r.at = at;
  const std::string header = ReadBytes(at + 4, header_len);
  r.fields = BagFields::Parse(header, location_, at + 4);
  const std::string data_length = ReadBytes(at + 4 + header_len, 4);
  r.data_len = ByteReader(data_length, location_, at + 4 + header_len).U32("data length");
  r.data_at = at + 8 + header_len;
  if (file_size_ - r.data_at < r.data_len) {
    location_.Fail(at, fmt::format("truncated: {} has {} data bytes, the file ends after {}", what,
                                   r.data_len, file_size_ - r.data_at));
  }
  r.end = r.data_at + r.data_len;
  return r;
}

std::string BagReader::ReadData(const Record& record) {
  return ReadBytes(record.data_at, record.data_len);
}

BagConnection BagReader::ParseConnection(const BagFields& fields, std::string_view data,
                                         const BagLocation& location, std::uint64_t data_at) {
  BagConnection c;
  c.id = fields.U32("conn");
  c.topic = std::string(fields.String("topic"));
  const BagFields header = BagFields::Parse(data, location, data_at);
  c.type = std::string(header.String("type"));
  c.md5sum = std::string(header.String("md5sum"));
  if (const auto definition = header.Find("message_definition")) {
    c.message_definition = std::string(*definition);
  }
  return c;
}

void BagReader::ReadIndex(std::uint64_t at, std::uint32_t connection_count,
                          std::uint32_t chunk_count) {
  // Every record takes at least 8 bytes: the counts cannot exceed what the index can hold.
  if ((std::uint64_t{connection_count} + chunk_count) * 8 > file_size_ - at) {
    location_.Fail(kBagMagic.size(),
                   fmt::format("{} connections and {} chunks do not fit the {} bytes of the index",
                               connection_count, chunk_count, file_size_ - at));
  }
  for (std::uint32_t i = 0; i < connection_count; ++i) {
    const Record r = ReadRecord(at, "a connection record of the index");
    RequireOp(r.fields, BagOp::kConnection, location_, at, "a connection record (index)");
    BagConnection c = ParseConnection(r.fields, ReadData(r), location_, r.data_at);
    for (const BagConnection& other : connections_) {
      if (other.id == c.id) location_.Fail(at, fmt::format("connection {} listed twice", c.id));
    }
    connections_.push_back(std::move(c));
    at = r.end;
  }
  std::sort(connections_.begin(), connections_.end(),
            [](const BagConnection& a, const BagConnection& b) { return a.id < b.id; });
  std::uint64_t previous_chunk = 0;
  for (std::uint32_t i = 0; i < chunk_count; ++i) {
    const Record r = ReadRecord(at, "a chunk info record of the index");
    RequireOp(r.fields, BagOp::kChunkInfo, location_, at, "a chunk info record (index)");
    if (const std::uint32_t version = r.fields.U32("ver"); version != 1) {
      location_.Fail(at, fmt::format("chunk info version {} (only 1 is known)", version));
    }
    BagChunkInfo info;
    info.chunk_pos = r.fields.U64("chunk_pos");
    info.start_ns = r.fields.TimeNs("start_time");
    info.end_ns = r.fields.TimeNs("end_time");
    const std::uint32_t count = r.fields.U32("count");
    if (std::uint64_t{count} * 8 != r.data_len) {
      location_.Fail(at, fmt::format("chunk info of {} connections holds {} bytes, not {}", count,
                                     r.data_len, std::uint64_t{count} * 8));
    }
    if (info.chunk_pos < std::max(first_record_, previous_chunk + 1) ||
        info.chunk_pos >= index_pos_) {
      location_.Fail(at, fmt::format("chunk info points to byte {}: not a chunk position "
                                     "(chunks lie between bytes {} and {}, in order)",
                                     info.chunk_pos, first_record_, index_pos_));
    }
    previous_chunk = info.chunk_pos;
    const std::string data = ReadData(r);
    ByteReader in(data, location_, r.data_at);
    for (std::uint32_t k = 0; k < count; ++k) {
      const std::uint32_t id = in.U32("connection id");
      const std::uint32_t messages = in.U32("message count");
      ConnectionById(id, location_, r.data_at);  // must be known
      for (const auto& [other, n] : info.counts) {
        if (other == id) location_.Fail(r.data_at, fmt::format("connection {} counted twice", id));
      }
      info.counts.emplace_back(id, messages);
    }
    chunk_infos_.push_back(std::move(info));
    at = r.end;
  }
  if (at != file_size_) {
    location_.Fail(at, fmt::format("{} bytes after the index", file_size_ - at));
  }
  for (BagConnection& c : connections_) {
    for (const BagChunkInfo& info : chunk_infos_) {
      for (const auto& [id, n] : info.counts) c.message_count += id == c.id ? n : 0;
    }
  }
}

const BagConnection& BagReader::ConnectionById(std::uint32_t id, const BagLocation& location,
                                               std::uint64_t at) const {
  const auto it =
      std::lower_bound(connections_.begin(), connections_.end(), id,
                       [](const BagConnection& c, std::uint32_t value) { return c.id < value; });
  if (it == connections_.end() || it->id != id) {
    location.Fail(at, fmt::format("connection {} is not in the bag's index", id));
  }
  return *it;
}

std::uint64_t BagReader::message_count() const {
  std::uint64_t n = 0;
  for (const BagConnection& c : connections_) n += c.message_count;
  return n;
}

std::vector<const BagConnection*> BagReader::ConnectionsOn(std::string_view topic) const {
  std::vector<const BagConnection*> out;
  for (const BagConnection& c : connections_) {
    if (c.topic == topic) out.push_back(&c);
  }
  return out;
}

std::string BagReader::DescribeTopics() const {
  std::string out;
  for (const BagConnection& c : connections_) {
    out += fmt::format("{}{} ({}, {} messages)", out.empty() ? "" : ", ", BagText(c.topic),
                       BagText(c.type), c.message_count);
  }
  return out.empty() ? "none" : out;
}

void BagReader::ReadMessages(const std::set<std::uint32_t>& wanted,
                             const std::function<void(const BagMessage&)>& on_message) {
  std::uint64_t at = first_record_;
  std::size_t chunk_index = 0;
  while (at < index_pos_) {
    const Record r = ReadRecord(at, "a chunk record");
    RequireOp(r.fields, BagOp::kChunk, location_, at, "a chunk");
    if (chunk_index >= chunk_infos_.size() || chunk_infos_[chunk_index].chunk_pos != at) {
      location_.Fail(at, "chunk not listed in the bag's index");
    }
    const BagChunkInfo& info = chunk_infos_[chunk_index++];
    const std::string_view compression_name = r.fields.String("compression");
    const std::optional<BagCompression> compression = ParseBagCompression(compression_name);
    if (!compression) {
      location_.Fail(at, fmt::format("unknown chunk compression '{}' (none, bz2, lz4)",
                                     BagText(compression_name)));
    }
    const std::uint32_t size = r.fields.U32("size");
    if (size > options_.max_chunk_bytes) {
      location_.Fail(at, fmt::format("chunk of {} bytes uncompressed, more than the reader's "
                                     "limit of {}",
                                     size, options_.max_chunk_bytes));
    }
    const bool read =
        wanted.empty() || std::any_of(info.counts.begin(), info.counts.end(),
                                      [&](const auto& c) { return wanted.count(c.first) > 0; });
    std::optional<ChunkEntries> entries;
    if (read) {
      const std::string chunk =
          DecompressChunk(*compression, ReadData(r), size, location_, r.data_at);
      const BagLocation in_chunk{location_.file, at};
      entries = ReadChunkRecords(chunk, in_chunk, wanted, on_message);
    }
    at = CheckIndexData(r.end, info, entries ? &*entries : nullptr);
  }
  if (chunk_index != chunk_infos_.size()) {
    location_.Fail(index_pos_, fmt::format("the index lists {} chunks, the file holds {}",
                                           chunk_infos_.size(), chunk_index));
  }
}

}  // namespace pkslam
