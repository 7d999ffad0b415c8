// The building blocks of ROS 1 bag format 2.0 files (http://wiki.ros.org/Bags/Format/2.0),
// shared by the reader (rosbag_reader.h), the writer (rosbag_writer.h) and the message codecs
// (ros_messages.h):
//   file    = "#ROSBAG V2.0\n" record*
//   record  = uint32 header_len, header, uint32 data_len, data
//   header  = field*;  field = uint32 field_len, name '=' value
// Every integer is little-endian. The header's "op" field (one byte) says what the record is.
// ByteReader is the one place where lengths read from a file are checked against the bytes
// that are there: a short read is an InputError naming the file and the byte offset.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace pkslam {

inline constexpr std::string_view kBagMagic = "#ROSBAG V2.0\n";
// The bag header record is padded with spaces to this many bytes of header plus data, so the
// writer can rewrite it in place once the index position is known.
inline constexpr std::size_t kBagHeaderRecordPadding = 4096;

// Record op codes.
enum class BagOp : std::uint8_t {
  kMessageDefinition = 0x01,  // bag format 1.2 only
  kMessageData = 0x02,
  kBagHeader = 0x03,
  kIndexData = 0x04,
  kChunk = 0x05,
  kChunkInfo = 0x06,
  kConnection = 0x07,
};

// Text from a bag for an error message (one line): printable ASCII as it is, any other byte as
// '?', at most 64 characters and then "...".
std::string BagText(std::string_view s);

// "chunk", "message data", ... or "unknown op code 0x2a".
std::string BagOpName(std::uint8_t op);

// Where bytes came from, for error messages: a file offset, or an offset into the uncompressed
// data of the chunk record that starts at `chunk_pos`.
struct BagLocation {
  std::filesystem::path file;
  std::optional<std::uint64_t> chunk_pos;

  // "byte 123" or "chunk at byte 4117, uncompressed byte 123".
  std::string Describe(std::uint64_t offset) const;
  // Throws InputError(file, "<Describe(offset)>: <what>").
  [[noreturn]] void Fail(std::uint64_t offset, const std::string& what) const;
};

// Bounds-checked little-endian reads from a byte range whose first byte is at `base` in
// `location` (its offsets in messages count from there).
class ByteReader {
 public:
  ByteReader(std::string_view data, const BagLocation& location, std::uint64_t base = 0)
      : data_(data), location_(&location), base_(base) {}

  std::uint8_t U8(std::string_view what);
  std::uint32_t U32(std::string_view what);
  std::uint64_t U64(std::string_view what);
  double F64(std::string_view what);
  // `n` bytes; InputError when fewer are left.
  std::string_view Bytes(std::uint64_t n, std::string_view what);
  // A ROS string or uint8[] array: uint32 length, then the bytes.
  std::string_view Sized(std::string_view what);
  // InputError unless every byte was read (a message with trailing bytes is not the type its
  // connection says).
  void RequireEnd(std::string_view what) const;

  std::size_t position() const { return position_; }
  std::size_t remaining() const { return data_.size() - position_; }
  // The offset of the next byte in the location's terms.
  std::uint64_t offset() const { return base_ + position_; }
  const BagLocation& location() const { return *location_; }
  [[noreturn]] void Fail(const std::string& what) const { location_->Fail(offset(), what); }

 private:
  std::string_view data_;
  const BagLocation* location_;
  std::uint64_t base_ = 0;
  std::size_t position_ = 0;
};

// A record header's fields in file order. Names are unique (a repeated name is an error).
class BagFields {
 public:
  // Parses a whole header; `at` is the header's offset (after its length) in `location`.
  static BagFields Parse(std::string_view header, const BagLocation& location, std::uint64_t at);

  std::optional<std::string_view> Find(std::string_view name) const;
  // The field's value; InputError naming the record offset when absent or of the wrong size.
  std::string_view String(std::string_view name) const;
  std::uint8_t U8(std::string_view name) const;
  std::uint32_t U32(std::string_view name) const;
  std::uint64_t U64(std::string_view name) const;
  // A ROS time field (uint32 secs, uint32 nsecs) in nanoseconds.
  std::int64_t TimeNs(std::string_view name) const;
  BagOp Op() const { return static_cast<BagOp>(U8("op")); }

  const std::vector<std::pair<std::string, std::string>>& fields() const { return fields_; }

 private:
  const std::string& Require(std::string_view name, std::size_t size) const;

  std::vector<std::pair<std::string, std::string>> fields_;
  const BagLocation* location_ = nullptr;
  std::uint64_t at_ = 0;
};

// Appending little-endian values and header fields (the writer and the message codecs).
void AppendU8(std::string* out, std::uint8_t v);
void AppendU32(std::string* out, std::uint32_t v);
void AppendU64(std::string* out, std::uint64_t v);
void AppendF64(std::string* out, double v);
// uint32 length + bytes; throws OptionError when longer than 4 GiB - 1.
void AppendSized(std::string* out, std::string_view bytes);
// A ROS time (uint32 secs, uint32 nsecs) from ns; OptionError when t_ns < 0 or beyond 2^32 s.
void AppendTime(std::string* out, std::int64_t t_ns);
// One header field: uint32 length, name, '=', value.
void AppendField(std::string* header, std::string_view name, std::string_view value);
std::string U8Bytes(std::uint8_t v);
std::string U32Bytes(std::uint32_t v);
std::string U64Bytes(std::uint64_t v);
std::string TimeBytes(std::int64_t t_ns);

// secs * 1e9 + nsecs; nullopt when nsecs >= 1e9 (not a normalised ROS time).
std::optional<std::int64_t> RosTimeToNs(std::uint32_t secs, std::uint32_t nsecs);

}  // namespace pkslam
