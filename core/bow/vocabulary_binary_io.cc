// pkslam's binary vocabulary format (all integers little-endian):
//   offset  0  magic "PKVOCAB\n" (8 bytes)
//           8  u32 version (1)
//          12  u32 k, u32 L, u32 scoring, u32 weighting (DBoW2 numbering)
//          28  u64 node count N (non-root nodes; the root is implicit as in the text format)
//          36  N records of 45 bytes: u32 parent, u8 leaf flag (0/1), 32 descriptor bytes,
//              f64 weight (IEEE-754 bits)
//   36 + 45 N  u64 checksum of all preceding bytes (FNV-1a style over 64-bit words)
// Loading is one read plus one pass: ~1M words load in well under 0.5 s.
#include <fmt/format.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "core/bow/vocabulary.h"
#include "core/bow/vocabulary_internal.h"
#include "core/util/error.h"
#include "core/util/output_file.h"

namespace pkslam {
namespace {

using bow_internal::kBinaryChecksumSize;
using bow_internal::kBinaryHeaderSize;
using bow_internal::kBinaryMagic;
using bow_internal::kBinaryNodeCountAt;
using bow_internal::kBinaryRecordSize;
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderSize = kBinaryHeaderSize;
constexpr std::size_t kRecordSize = kBinaryRecordSize;
constexpr std::size_t kChecksumSize = kBinaryChecksumSize;
constexpr const auto& kMagic = kBinaryMagic;

template <typename T>
void PutLE(std::string* out, T value) {
  using U = std::make_unsigned_t<T>;
  U u = static_cast<U>(value);
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    out->push_back(static_cast<char>(u & 0xFF));
    if constexpr (sizeof(T) > 1) u = static_cast<U>(u >> 8);
  }
}

template <typename T>
T GetLE(const unsigned char* p) {
  using U = std::make_unsigned_t<T>;
  U u = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) u = static_cast<U>(u | (U(p[i]) << (8 * i)));
  return static_cast<T>(u);
}

std::vector<unsigned char> ReadBytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(file, "cannot open vocabulary file");
  const std::streamoff size = in.tellg();
  if (size < 0) throw InputError(file, "cannot determine file size");
  std::vector<unsigned char> data(static_cast<std::size_t>(size));
  in.seekg(0);
  if (!data.empty() && !in.read(reinterpret_cast<char*>(data.data()), size)) {
    throw InputError(file, "read error");
  }
  return data;
}

InputError AtOffset(const std::filesystem::path& file, std::size_t offset,
                    const std::string& what) {
  return InputError(file, fmt::format("offset {}: {}", offset, what));
}

}  // namespace

std::uint64_t bow_internal::BinaryChecksum(const unsigned char* data, std::size_t size) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  constexpr std::uint64_t kPrime = 0x100000001b3ULL;
  std::size_t i = 0;
  for (; i + 8 <= size; i += 8) {
    h ^= GetLE<std::uint64_t>(data + i);
    h *= kPrime;
    h ^= h >> 29;
  }
  for (; i < size; ++i) {
    h ^= data[i];
    h *= kPrime;
  }
  return h;
}

bool IsBinaryVocabularyFile(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::array<char, 8> head{};
  return in.read(head.data(), head.size()) && head == kMagic;
}

Vocabulary Vocabulary::LoadBinary(const std::filesystem::path& file) {
  const std::vector<unsigned char> data = ReadBytes(file);
  const unsigned char* p = data.data();
  if (data.size() < kMagic.size() || std::memcmp(p, kMagic.data(), kMagic.size()) != 0) {
    throw AtOffset(file, 0, "not a pkslam binary vocabulary (bad magic)");
  }
  if (data.size() < kHeaderSize) {
    throw AtOffset(file, data.size(),
                   fmt::format("truncated header ({} of {} bytes)", data.size(), kHeaderSize));
  }
  const auto version = GetLE<std::uint32_t>(p + 8);
  if (version != kVersion) {
    throw AtOffset(file, 8,
                   fmt::format("unsupported format version {} (expected {})", version, kVersion));
  }
  VocabularyParams params;
  params.branching = static_cast<int>(GetLE<std::uint32_t>(p + 12));
  params.levels = static_cast<int>(GetLE<std::uint32_t>(p + 16));
  params.scoring = static_cast<Scoring>(GetLE<std::uint32_t>(p + 20));
  params.weighting = static_cast<Weighting>(GetLE<std::uint32_t>(p + 24));
  if (auto problem = bow_internal::ParamsProblem(params)) throw AtOffset(file, 12, *problem);
  const auto count = GetLE<std::uint64_t>(p + kBinaryNodeCountAt);
  const std::size_t room = (data.size() - kHeaderSize) / kRecordSize;
  if (count > room || data.size() < kHeaderSize + count * kRecordSize + kChecksumSize) {
    throw AtOffset(
        file, data.size(),
        fmt::format("truncated: header declares {} nodes ({} bytes), file has {} bytes", count,
                    kHeaderSize + count * kRecordSize + kChecksumSize, data.size()));
  }
  const std::size_t checksum_at = kHeaderSize + count * kRecordSize;
  if (data.size() != checksum_at + kChecksumSize) {
    throw AtOffset(file, checksum_at + kChecksumSize,
                   fmt::format("{} trailing bytes after the checksum",
                               data.size() - checksum_at - kChecksumSize));
  }
  if (GetLE<std::uint64_t>(p + checksum_at) != bow_internal::BinaryChecksum(p, checksum_at)) {
    throw AtOffset(file, checksum_at, "checksum mismatch: the file is corrupt");
  }

  std::vector<VocabularyNode> nodes(static_cast<std::size_t>(count) + 1);
  for (std::size_t i = 1; i <= count; ++i) {
    const std::size_t at = kHeaderSize + (i - 1) * kRecordSize;
    const unsigned char* r = p + at;
    VocabularyNode& n = nodes[i];
    n.parent = GetLE<std::uint32_t>(r);
    if (r[4] > 1) throw AtOffset(file, at + 4, fmt::format("leaf flag {} is not 0 or 1", r[4]));
    n.is_leaf = r[4] == 1;
    std::memcpy(n.descriptor.bytes.data(), r + 5, 32);
    n.weight = std::bit_cast<double>(GetLE<std::uint64_t>(r + 37));
  }
  if (auto problem = bow_internal::FindTreeProblem(params, nodes)) {
    const std::size_t at = problem->node == 0 ? 0 : kHeaderSize + (problem->node - 1) * kRecordSize;
    throw AtOffset(file, at, fmt::format("node {}: {}", problem->node, problem->message));
  }
  return FromValidNodes(params, std::move(nodes));
}

void Vocabulary::SaveBinary(const std::filesystem::path& file) const {
  PKSLAM_CHECK(!empty(), "cannot save an empty vocabulary to {}", file.string());
  std::string out;
  const std::size_t count = node_count() - (node_count() > 0 ? 1 : 0);
  out.reserve(kHeaderSize + count * kRecordSize + kChecksumSize);
  out.append(kMagic.data(), kMagic.size());
  PutLE<std::uint32_t>(&out, kVersion);
  PutLE<std::uint32_t>(&out, static_cast<std::uint32_t>(params_.branching));
  PutLE<std::uint32_t>(&out, static_cast<std::uint32_t>(params_.levels));
  PutLE<std::uint32_t>(&out, static_cast<std::uint32_t>(params_.scoring));
  PutLE<std::uint32_t>(&out, static_cast<std::uint32_t>(params_.weighting));
  PutLE<std::uint64_t>(&out, count);
  for (std::size_t i = 1; i < node_count(); ++i) {
    PutLE<std::uint32_t>(&out, parents_[i]);
    out.push_back(node_words_[i] != kNoWord ? 1 : 0);
    out.append(reinterpret_cast<const char*>(descriptors_[i].bytes.data()), 32);
    PutLE<std::uint64_t>(&out, std::bit_cast<std::uint64_t>(weights_[i]));
  }
  PutLE<std::uint64_t>(&out, bow_internal::BinaryChecksum(
                                 reinterpret_cast<const unsigned char*>(out.data()), out.size()));
  WriteFileAtomically(file, out);
}

Vocabulary Vocabulary::Load(const std::filesystem::path& file) {
  if (!std::filesystem::exists(file)) throw InputError(file, "vocabulary file does not exist");
  return IsBinaryVocabularyFile(file) ? LoadBinary(file) : LoadText(file);
}

void Vocabulary::Save(const std::filesystem::path& file) const {
  const std::string ext = file.extension().string();
  if (ext == ".txt") {
    SaveText(file);
  } else if (ext == ".bin" || ext == ".pkvoc") {
    SaveBinary(file);
  } else {
    throw OptionError(fmt::format(
        "vocabulary file '{}': unknown extension '{}' (use .txt for DBoW2 text, .bin or .pkvoc "
        "for binary)",
        file.string(), ext));
  }
}

}  // namespace pkslam
