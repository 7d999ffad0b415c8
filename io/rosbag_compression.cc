#include "io/rosbag_compression.h"

#include <bzlib.h>
#include <fmt/format.h>
#include <lz4frame.h>

#include <algorithm>
#include <limits>
#include <memory>

#include "core/util/error.h"

namespace pkslam {
namespace {

// Output buffers start at this size (or the expected size, if smaller) and double.
constexpr std::size_t kInitialOutput = 1 << 20;

// An output buffer that may grow to `size` + 1 bytes: one more than expected is how an
// overlong stream is noticed.
class GrowingOutput {
 public:
  explicit GrowingOutput(std::uint64_t size)
      : limit_(size + 1), buffer_(std::min<std::uint64_t>(limit_, kInitialOutput), '\0') {}

  char* free_begin() { return buffer_.data() + used_; }
  std::size_t free_size() const { return buffer_.size() - used_; }
  void Produced(std::size_t n) { used_ += n; }
  // Doubles the buffer (up to the limit); false when it is at the limit already.
  bool Grow() {
    if (buffer_.size() >= limit_) return false;
    buffer_.resize(std::min<std::uint64_t>(limit_, 2 * buffer_.size()));
    return true;
  }
  std::size_t used() const { return used_; }
  std::string Take() {
    buffer_.resize(used_);
    return std::move(buffer_);
  }

 private:
  std::uint64_t limit_;
  std::string buffer_;
  std::size_t used_ = 0;
};

std::string DecompressBz2(std::string_view data, std::uint64_t size, const BagLocation& location,
                          std::uint64_t at) {
  if (data.size() > std::numeric_limits<unsigned>::max()) {
    location.Fail(at, "bz2 chunk larger than libbz2 takes in one call");
  }
  bz_stream stream{};
  if (BZ2_bzDecompressInit(&stream, 0, 0) != BZ_OK) throw Error("BZ2_bzDecompressInit failed");
  const std::unique_ptr<bz_stream, void (*)(bz_stream*)> end(
      &stream, [](bz_stream* s) { BZ2_bzDecompressEnd(s); });
  stream.next_in = const_cast<char*>(data.data());  // libbz2's API is not const-correct
  stream.avail_in = static_cast<unsigned>(data.size());
  GrowingOutput out(size);
  while (true) {
    const std::size_t window = std::min<std::size_t>(out.free_size(), 1u << 30);
    stream.next_out = out.free_begin();
    stream.avail_out = static_cast<unsigned>(window);
    const int rc = BZ2_bzDecompress(&stream);
    out.Produced(window - stream.avail_out);
    if (rc == BZ_STREAM_END) break;
    if (rc != BZ_OK) location.Fail(at, fmt::format("corrupt bz2 data (libbz2 error {})", rc));
    if (out.free_size() == 0) {
      if (!out.Grow()) break;  // more than `size`: reported below
    } else if (stream.avail_in == 0) {
      location.Fail(at, fmt::format("bz2 data ends after {} of {} bytes", out.used(), size));
    }
  }
  if (out.used() != size) {
    location.Fail(at, fmt::format("bz2 data holds {}{} bytes, the chunk's size field says {}",
                                  out.used() > size ? "more than " : "",
                                  std::min<std::uint64_t>(out.used(), size), size));
  }
  if (stream.avail_in != 0) {
    location.Fail(at, fmt::format("{} bytes after the end of the bz2 data", stream.avail_in));
  }
  return out.Take();
}

std::string DecompressLz4(std::string_view data, std::uint64_t size, const BagLocation& location,
                          std::uint64_t at) {
  LZ4F_dctx* context = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&context, LZ4F_VERSION))) {
    throw Error("LZ4F_createDecompressionContext failed");
  }
  const std::unique_ptr<LZ4F_dctx, LZ4F_errorCode_t (*)(LZ4F_dctx*)> free(
      context, LZ4F_freeDecompressionContext);
  GrowingOutput out(size);
  std::size_t consumed = 0;
  bool complete = false;
  while (!complete) {
    std::size_t dst = out.free_size();
    std::size_t src = data.size() - consumed;
    const std::size_t rc =
        LZ4F_decompress(context, out.free_begin(), &dst, data.data() + consumed, &src, nullptr);
    if (LZ4F_isError(rc)) {
      location.Fail(at, fmt::format("corrupt lz4 data ({})", LZ4F_getErrorName(rc)));
    }
    consumed += src;
    out.Produced(dst);
    complete = rc == 0;
    if (complete) break;
    if (src == 0 && dst == 0 && out.free_size() > 0) {
      location.Fail(at, fmt::format("lz4 data stalls after {} of {} bytes", out.used(), size));
    }
    if (out.free_size() == 0) {
      if (!out.Grow()) break;  // more than `size`: reported below
    } else if (consumed == data.size()) {
      location.Fail(at, fmt::format("lz4 data ends after {} of {} bytes", out.used(), size));
    }
  }
  if (out.used() != size) {
    location.Fail(at, fmt::format("lz4 data holds {}{} bytes, the chunk's size field says {}",
                                  out.used() > size ? "more than " : "",
                                  std::min<std::uint64_t>(out.used(), size), size));
  }
  if (consumed != data.size()) {
    location.Fail(at,
                  fmt::format("{} bytes after the end of the lz4 frame", data.size() - consumed));
  }
  return out.Take();
}

}  // namespace

std::string_view BagCompressionName(BagCompression compression) {
  switch (compression) {
    case BagCompression::kNone:
      return "none";
    case BagCompression::kBz2:
      return "bz2";
    case BagCompression::kLz4:
      return "lz4";
  }
  return "?";
}

std::optional<BagCompression> ParseBagCompression(std::string_view name) {
  for (const BagCompression c :
       {BagCompression::kNone, BagCompression::kBz2, BagCompression::kLz4}) {
    if (name == BagCompressionName(c)) return c;
  }
  return std::nullopt;
}

std::string CompressChunk(BagCompression compression, std::string_view data) {
  switch (compression) {
    case BagCompression::kNone:
      return std::string(data);
    case BagCompression::kBz2: {
      if (data.size() > std::numeric_limits<unsigned>::max() / 2) {
        throw OptionError(fmt::format("a {} byte chunk is too large for bz2", data.size()));
      }
      // libbz2's documented bound: 1% more than the input plus 600 bytes.
      std::string out(data.size() + data.size() / 100 + 601, '\0');
      auto out_size = static_cast<unsigned>(out.size());
      const int rc = BZ2_bzBuffToBuffCompress(out.data(), &out_size, const_cast<char*>(data.data()),
                                              static_cast<unsigned>(data.size()), 9, 0, 30);
      if (rc != BZ_OK) throw Error(fmt::format("bz2 compression failed (libbz2 error {})", rc));
      out.resize(out_size);
      return out;
    }
    case BagCompression::kLz4: {
      LZ4F_preferences_t preferences{};
      preferences.frameInfo.blockSizeID = LZ4F_max1MB;
      preferences.frameInfo.blockMode = LZ4F_blockIndependent;
      preferences.frameInfo.contentChecksumFlag = LZ4F_contentChecksumEnabled;
      preferences.frameInfo.blockChecksumFlag = LZ4F_noBlockChecksum;
      std::string out(LZ4F_compressFrameBound(data.size(), &preferences), '\0');
      const std::size_t n =
          LZ4F_compressFrame(out.data(), out.size(), data.data(), data.size(), &preferences);
      if (LZ4F_isError(n)) {
        throw Error(fmt::format("lz4 compression failed ({})", LZ4F_getErrorName(n)));
      }
      out.resize(n);
      return out;
    }
  }
  throw Error("unknown bag compression");
}

std::string DecompressChunk(BagCompression compression, std::string_view data, std::uint64_t size,
                            const BagLocation& location, std::uint64_t at) {
  switch (compression) {
    case BagCompression::kNone:
      if (data.size() != size) {
        location.Fail(at, fmt::format("uncompressed chunk holds {} bytes, its size field says {}",
                                      data.size(), size));
      }
      return std::string(data);
    case BagCompression::kBz2:
      return DecompressBz2(data, size, location, at);
    case BagCompression::kLz4:
      return DecompressLz4(data, size, location, at);
  }
  throw Error("unknown bag compression");
}

}  // namespace pkslam
