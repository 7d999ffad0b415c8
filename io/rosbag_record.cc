#include "io/rosbag_record.h"

#include <fmt/format.h>

#include <bit>
#include <cstring>
#include <limits>

#include "core/util/error.h"

namespace pkslam {

static_assert(std::endian::native == std::endian::little,
              "the bag codecs copy little-endian values as they are in memory");

namespace {

std::string Printable(std::string_view s) { return fmt::format("'{}'", BagText(s)); }

template <typename T>
T Load(std::string_view bytes) {
  T v;
  std::memcpy(&v, bytes.data(), sizeof(T));
  return v;
}

template <typename T>
void Store(std::string* out, T v) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &v, sizeof(T));
  out->append(bytes, sizeof(T));
}

constexpr std::int64_t kNsPerSecond = 1'000'000'000;

}  // namespace

std::string BagText(std::string_view s) {
  std::string out;
  for (const char c : s.substr(0, 64)) out.push_back(c >= 0x20 && c <= 0x7e ? c : '?');
  if (s.size() > 64) out.append(3, '.');
  return out;
}

std::string BagLocation::Describe(std::uint64_t offset) const {
  return chunk_pos ? fmt::format("chunk at byte {}, uncompressed byte {}", *chunk_pos, offset)
                   : fmt::format("byte {}", offset);
}

void BagLocation::Fail(std::uint64_t offset, const std::string& what) const {
  throw InputError(file, fmt::format("{}: {}", Describe(offset), what));
}

std::string_view ByteReader::Bytes(std::uint64_t n, std::string_view what) {
  if (n > remaining()) {
    Fail(fmt::format("truncated: {} needs {} bytes, {} left", what, n, remaining()));
  }
  const std::string_view out = data_.substr(position_, n);
  position_ += n;
  return out;
}

std::uint8_t ByteReader::U8(std::string_view what) { return Load<std::uint8_t>(Bytes(1, what)); }
std::uint32_t ByteReader::U32(std::string_view what) { return Load<std::uint32_t>(Bytes(4, what)); }
std::uint64_t ByteReader::U64(std::string_view what) { return Load<std::uint64_t>(Bytes(8, what)); }
double ByteReader::F64(std::string_view what) { return Load<double>(Bytes(8, what)); }

std::string_view ByteReader::Sized(std::string_view what) {
  const std::uint64_t at = offset();
  const std::uint32_t n = U32(what);
  if (n > remaining()) {
    location_->Fail(at, fmt::format("{}: length {} but only {} bytes left", what, n, remaining()));
  }
  return Bytes(n, what);
}

void ByteReader::RequireEnd(std::string_view what) const {
  if (remaining() != 0) Fail(fmt::format("{}: {} bytes left over", what, remaining()));
}

BagFields BagFields::Parse(std::string_view header, const BagLocation& location, std::uint64_t at) {
  BagFields f;
  f.location_ = &location;
  f.at_ = at;
  ByteReader in(header, location, at);
  while (in.remaining() > 0) {
    const std::uint64_t field_at = in.offset();
    const std::string_view field = in.Sized("header field");
    const std::size_t eq = field.find('=');
    if (eq == std::string_view::npos || eq == 0) {
      location.Fail(field_at, fmt::format("header field {} is not name=value", Printable(field)));
    }
    const std::string_view name = field.substr(0, eq);
    if (f.Find(name)) {
      location.Fail(field_at, fmt::format("header field {} given twice", Printable(name)));
    }
    f.fields_.emplace_back(std::string(name), std::string(field.substr(eq + 1)));
  }
  return f;
}

std::optional<std::string_view> BagFields::Find(std::string_view name) const {
  for (const auto& [n, v] : fields_) {
    if (n == name) return std::string_view(v);
  }
  return std::nullopt;
}

const std::string& BagFields::Require(std::string_view name, std::size_t size) const {
  for (const auto& [n, v] : fields_) {
    if (n != name) continue;
    if (size > 0 && v.size() != size) {
      location_->Fail(at_,
                      fmt::format("header field '{}' has {} bytes, not {}", name, v.size(), size));
    }
    return v;
  }
  location_->Fail(at_, fmt::format("record header has no '{}' field", name));
}

std::string_view BagFields::String(std::string_view name) const { return Require(name, 0); }
std::uint8_t BagFields::U8(std::string_view name) const {
  return Load<std::uint8_t>(Require(name, 1));
}
std::uint32_t BagFields::U32(std::string_view name) const {
  return Load<std::uint32_t>(Require(name, 4));
}
std::uint64_t BagFields::U64(std::string_view name) const {
  return Load<std::uint64_t>(Require(name, 8));
}

std::int64_t BagFields::TimeNs(std::string_view name) const {
  const std::string& v = Require(name, 8);
  const auto secs = Load<std::uint32_t>(std::string_view(v).substr(0, 4));
  const auto nsecs = Load<std::uint32_t>(std::string_view(v).substr(4, 4));
  const std::optional<std::int64_t> t = RosTimeToNs(secs, nsecs);
  if (!t) location_->Fail(at_, fmt::format("header field '{}': nsecs {} >= 1e9", name, nsecs));
  return *t;
}

void AppendU8(std::string* out, std::uint8_t v) { Store(out, v); }
void AppendU32(std::string* out, std::uint32_t v) { Store(out, v); }
void AppendU64(std::string* out, std::uint64_t v) { Store(out, v); }
void AppendF64(std::string* out, double v) { Store(out, v); }

void AppendSized(std::string* out, std::string_view bytes) {
  if (bytes.size() > std::numeric_limits<std::uint32_t>::max()) {
    throw OptionError(fmt::format("{} bytes do not fit a ROS length field", bytes.size()));
  }
  AppendU32(out, static_cast<std::uint32_t>(bytes.size()));
  out->append(bytes);
}

void AppendTime(std::string* out, std::int64_t t_ns) {
  constexpr std::int64_t kMaxNs =
      (static_cast<std::int64_t>(std::numeric_limits<std::uint32_t>::max()) + 1) * kNsPerSecond;
  if (t_ns < 0 || t_ns >= kMaxNs) {
    throw OptionError(fmt::format("time {} ns is outside a ROS time (0 to 2^32 s)", t_ns));
  }
  AppendU32(out, static_cast<std::uint32_t>(t_ns / kNsPerSecond));
  AppendU32(out, static_cast<std::uint32_t>(t_ns % kNsPerSecond));
}

void AppendField(std::string* header, std::string_view name, std::string_view value) {
  std::string field(name);
  field += '=';
  field.append(value);
  AppendSized(header, field);
}

std::string U8Bytes(std::uint8_t v) {
  std::string s;
  AppendU8(&s, v);
  return s;
}
std::string U32Bytes(std::uint32_t v) {
  std::string s;
  AppendU32(&s, v);
  return s;
}
std::string U64Bytes(std::uint64_t v) {
  std::string s;
  AppendU64(&s, v);
  return s;
}
std::string TimeBytes(std::int64_t t_ns) {
  std::string s;
  AppendTime(&s, t_ns);
  return s;
}

std::string BagOpName(std::uint8_t op) {
  switch (static_cast<BagOp>(op)) {
    case BagOp::kMessageDefinition:
      return "message definition (format 1.2)";
    case BagOp::kMessageData:
      return "message data";
    case BagOp::kBagHeader:
      return "bag header";
    case BagOp::kIndexData:
      return "index data";
    case BagOp::kChunk:
      return "chunk";
    case BagOp::kChunkInfo:
      return "chunk info";
    case BagOp::kConnection:
      return "connection";
  }
  return fmt::format("unknown op code 0x{:02x}", op);
}

std::optional<std::int64_t> RosTimeToNs(std::uint32_t secs, std::uint32_t nsecs) {
  if (nsecs >= kNsPerSecond) return std::nullopt;
  return static_cast<std::int64_t>(secs) * kNsPerSecond + nsecs;
}

}  // namespace pkslam
