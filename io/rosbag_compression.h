// Chunk compression of ROS 1 bags: none, bz2 (libbz2, one bzip2 stream) and lz4 (liblz4's frame
// format, which is what ROS's roslz4 writes and reads: independent blocks, a content checksum,
// no block checksums, no content size; roslz4 refuses frames with other flags).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "io/rosbag_record.h"

namespace pkslam {

enum class BagCompression { kNone, kBz2, kLz4 };

// "none", "bz2", "lz4": the chunk header's "compression" values.
std::string_view BagCompressionName(BagCompression compression);
std::optional<BagCompression> ParseBagCompression(std::string_view name);

std::string CompressChunk(BagCompression compression, std::string_view data);

// The chunk's `size` bytes from its compressed `data` (at offset `at` of `location`). The output
// grows with what the data really holds, so a corrupt size field allocates nothing extra.
// InputError naming the offset when the data is corrupt, ends early, holds more or fewer than
// `size` bytes, or has bytes after its end.
std::string DecompressChunk(BagCompression compression, std::string_view data, std::uint64_t size,
                            const BagLocation& location, std::uint64_t at);

}  // namespace pkslam
