#include "io/rosbag_writer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <limits>

#include "core/util/error.h"

namespace pkslam {

namespace fs = std::filesystem;

namespace {

std::string OpField(BagOp op) { return U8Bytes(static_cast<std::uint8_t>(op)); }

}  // namespace

void BagWriterOptions::Check() const {
  PKSLAM_CHECK_OPTION(chunk_bytes > 0 && chunk_bytes <= (std::size_t{1} << 30), "chunk_bytes", "{}",
                      chunk_bytes);
}

BagWriter::BagWriter(fs::path file, const BagWriterOptions& options)
    : file_(std::move(file)), options_(options) {
  options_.Check();
  partial_ = file_;
  partial_ += ".partial";
  out_.open(partial_, std::ios::binary | std::ios::trunc);
  if (!out_) throw OutputError(file_, std::strerror(errno));
  out_.write(kBagMagic.data(), static_cast<std::streamsize>(kBagMagic.size()));
  position_ = kBagMagic.size();
  WriteBagHeader(0);  // rewritten by Close()
  Require("the bag header");
}

BagWriter::~BagWriter() {
  if (!closed_) {
    out_.close();
    std::error_code ec;
    fs::remove(partial_, ec);
  }
}

void BagWriter::Require(std::string_view what) {
  if (!out_) throw OutputError(file_, fmt::format("writing {}: {}", what, std::strerror(errno)));
}

void BagWriter::WriteRecord(std::string_view header, std::string_view data) {
  std::string lengths;
  AppendSized(&lengths, header);
  out_.write(lengths.data(), static_cast<std::streamsize>(lengths.size()));
  lengths.clear();
  AppendU32(&lengths, static_cast<std::uint32_t>(data.size()));
  out_.write(lengths.data(), static_cast<std::streamsize>(lengths.size()));
  out_.write(data.data(), static_cast<std::streamsize>(data.size()));
  position_ += 8 + header.size() + data.size();
}

void BagWriter::WriteBagHeader(std::uint64_t index_pos) {
  std::string header;
  AppendField(&header, "op", OpField(BagOp::kBagHeader));
  AppendField(&header, "index_pos", U64Bytes(index_pos));
  AppendField(&header, "conn_count", U32Bytes(static_cast<std::uint32_t>(connections_.size())));
  AppendField(&header, "chunk_count", U32Bytes(static_cast<std::uint32_t>(chunk_infos_.size())));
  // Header and padding fill kBagHeaderRecordPadding bytes, whatever the values.
  WriteRecord(header, std::string(kBagHeaderRecordPadding - header.size(), ' '));
}

std::uint32_t BagWriter::AddConnection(std::string topic, const RosMessageType& type) {
  if (closed_) throw Error("BagWriter::AddConnection after Close");
  connections_.push_back({std::move(topic), type, false});
  return static_cast<std::uint32_t>(connections_.size() - 1);
}

// A connection record's header and data (in the chunk where the connection first writes, and
// again after the chunks).
std::pair<std::string, std::string> BagWriter::ConnectionRecord(std::uint32_t id,
                                                                const Connection& c) {
  std::string header;
  AppendField(&header, "op", OpField(BagOp::kConnection));
  AppendField(&header, "conn", U32Bytes(id));
  AppendField(&header, "topic", c.topic);
  std::string data;
  AppendField(&data, "topic", c.topic);
  AppendField(&data, "type", c.type.name);
  AppendField(&data, "md5sum", c.type.md5sum);
  AppendField(&data, "message_definition", c.type.definition);
  return {std::move(header), std::move(data)};
}

void BagWriter::Write(std::uint32_t connection, std::int64_t t_ns, std::string_view message) {
  PKSLAM_CHECK(!closed_ && connection < connections_.size(), "connection {} of {}", connection,
               connections_.size());
  const std::string time = TimeBytes(t_ns);  // OptionError before anything is changed
  Connection& c = connections_[connection];
  if (!c.recorded) {
    const auto [header, data] = ConnectionRecord(connection, c);
    AppendSized(&chunk_, header);
    AppendSized(&chunk_, data);
    c.recorded = true;
  }
  if (chunk_info_.counts.empty()) {
    chunk_info_.start_ns = t_ns;
    chunk_info_.end_ns = t_ns;
  }
  chunk_info_.start_ns = std::min(chunk_info_.start_ns, t_ns);
  chunk_info_.end_ns = std::max(chunk_info_.end_ns, t_ns);
  ++chunk_info_.counts[connection];
  chunk_index_[connection].emplace_back(t_ns, static_cast<std::uint32_t>(chunk_.size()));
  std::string header;
  AppendField(&header, "op", OpField(BagOp::kMessageData));
  AppendField(&header, "conn", U32Bytes(connection));
  AppendField(&header, "time", time);
  AppendSized(&chunk_, header);
  AppendSized(&chunk_, message);
  ++messages_;
  if (chunk_.size() >= options_.chunk_bytes) FlushChunk();
}

void BagWriter::FlushChunk() {
  if (chunk_info_.counts.empty()) return;
  if (chunk_.size() > std::numeric_limits<std::uint32_t>::max()) {
    throw OptionError(fmt::format("{}: a chunk of {} bytes (a message of more than 4 GB?)",
                                  file_.string(), chunk_.size()));
  }
  chunk_info_.chunk_pos = position_;
  const std::string data = CompressChunk(options_.compression, chunk_);
  std::string header;
  AppendField(&header, "op", OpField(BagOp::kChunk));
  AppendField(&header, "compression", BagCompressionName(options_.compression));
  AppendField(&header, "size", U32Bytes(static_cast<std::uint32_t>(chunk_.size())));
  WriteRecord(header, data);
  for (const auto& [id, entries] : chunk_index_) {
    std::string index_header;
    AppendField(&index_header, "op", OpField(BagOp::kIndexData));
    AppendField(&index_header, "ver", U32Bytes(1));
    AppendField(&index_header, "conn", U32Bytes(id));
    AppendField(&index_header, "count", U32Bytes(static_cast<std::uint32_t>(entries.size())));
    std::string index;
    for (const auto& [t_ns, offset] : entries) {
      AppendTime(&index, t_ns);
      AppendU32(&index, offset);
    }
    WriteRecord(index_header, index);
  }
  Require("a chunk");
  chunk_infos_.push_back(std::move(chunk_info_));
  chunk_info_ = {};
  chunk_.clear();
  chunk_index_.clear();
}

void BagWriter::Close() {
  if (closed_) return;
  FlushChunk();
  const std::uint64_t index_pos = position_;
  // The format repeats every connection record after the chunks (the reader's index).
  for (std::uint32_t id = 0; id < connections_.size(); ++id) {
    const auto [header, data] = ConnectionRecord(id, connections_[id]);
    WriteRecord(header, data);
  }
  for (const ChunkInfo& info : chunk_infos_) {
    std::string header;
    AppendField(&header, "op", OpField(BagOp::kChunkInfo));
    AppendField(&header, "ver", U32Bytes(1));
    AppendField(&header, "chunk_pos", U64Bytes(info.chunk_pos));
    AppendField(&header, "start_time", TimeBytes(info.start_ns));
    AppendField(&header, "end_time", TimeBytes(info.end_ns));
    AppendField(&header, "count", U32Bytes(static_cast<std::uint32_t>(info.counts.size())));
    std::string data;
    for (const auto& [id, count] : info.counts) {
      AppendU32(&data, id);
      AppendU32(&data, count);
    }
    WriteRecord(header, data);
  }
  Require("the index");
  const std::uint64_t end = position_;
  out_.seekp(static_cast<std::streamoff>(kBagMagic.size()));
  position_ = kBagMagic.size();
  WriteBagHeader(index_pos);
  position_ = end;
  out_.flush();
  Require("the bag header");
  out_.close();
  if (!out_) throw OutputError(file_, std::strerror(errno));
  std::error_code ec;
  fs::rename(partial_, file_, ec);
  if (ec) throw OutputError(file_, ec.message());
  closed_ = true;
}

}  // namespace pkslam
