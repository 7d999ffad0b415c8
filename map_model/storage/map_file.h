// Map files (`pkslam run --save-map / --load-map`): an AtlasRecord in a versioned binary file.
//
// Layout (little-endian):
//   bytes 0-7    magic "PKSLAMAP"
//   bytes 8-11   format version (uint32, kMapFileVersion)
//   bytes 12-19  payload size in bytes (uint64)
//   bytes 20-23  CRC-32 of the payload (zlib's crc32)
//   bytes 24-    payload: the AtlasRecord in cereal's portable binary archive
// The payload is cereal (Debian libcereal-dev, header-only, maintained): its portable binary
// archive fixes byte order and integer widths, and its versioned serialize functions keep old
// files readable when records grow. The header around it lets a reader reject a truncated or
// corrupted file before cereal sees a byte, with a one-line error.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "core/sensor/camera_rig.h"
#include "map_model/storage/map_records.h"

namespace pkslam {

// Version 2 appends the map's calibration (AtlasRecord::calibration) to version 1's payload,
// version 3 the gyro's scale-factor error after it, version 4 the accelerometer's axis errors
// after that; older files still read (without them).
inline constexpr std::uint32_t kMapFileVersion = 4;
inline constexpr std::uint32_t kOldestMapFileVersion = 1;

// Writes atomically (a partial file never replaces a good one). Throws OutputError.
void WriteMapFile(const std::filesystem::path& file, const AtlasRecord& record);

// Throws InputError naming the file: missing, not a map file, another format version,
// truncated, checksum mismatch, or a payload that does not decode.
AtlasRecord ReadMapFile(const std::filesystem::path& file);

// Whether a map made with (record's vocabulary, record.camera) may be used by a run with
// (vocabulary_fingerprint, rig): same vocabulary, same sensor kind and the same camera
// (intrinsics within 1e-6 relative, same model line, same extrinsics). Throws InputError naming
// the file and the first difference.
void CheckCompatible(const std::filesystem::path& file, const AtlasRecord& record,
                     std::uint64_t vocabulary_fingerprint, const CameraRig& rig);

}  // namespace pkslam
