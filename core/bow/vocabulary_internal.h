// Helpers shared by the vocabulary's construction, file formats and training (not public API).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/bow/vocabulary.h"

// GCC/Clang on x86-64 without -mpopcnt turn std::popcount into a library call. The Hamming
// hot loops are therefore compiled twice, with POPCNT and for the baseline, and picked per
// call with CpuHasPopcnt() (explicit dispatch, as core/features does, rather than ifunc
// target_clones, whose resolvers run before sanitizer runtimes are initialised).
#if defined(__x86_64__) && defined(__GNUC__)
#define PKSLAM_TARGET_POPCNT [[gnu::target("popcnt")]]
#else
#define PKSLAM_TARGET_POPCNT
#endif

namespace pkslam::bow_internal {

// Whether the running CPU has the POPCNT instruction (a cached flag read, cheap per call).
inline bool CpuHasPopcnt() {
#if defined(__x86_64__) && defined(__GNUC__)
  return __builtin_cpu_supports("popcnt");
#else
  return false;
#endif
}

// pkslam's binary format (vocabulary_binary_io.cc): magic and header, one record per node
// after the root, then a checksum of every byte before it (little-endian u64). Shared with
// the vocabulary fuzzer (fuzz/), which repairs inputs to reach the checks behind it.
inline constexpr std::array<char, 8> kBinaryMagic = {'P', 'K', 'V', 'O', 'C', 'A', 'B', '\n'};
inline constexpr std::size_t kBinaryHeaderSize = 36;
inline constexpr std::size_t kBinaryNodeCountAt = 28;  // u64 in the header
inline constexpr std::size_t kBinaryRecordSize = 45;
inline constexpr std::size_t kBinaryChecksumSize = 8;
std::uint64_t BinaryChecksum(const unsigned char* data, std::size_t size);

// Limits we accept in files and options.
inline constexpr int kMaxBranching = 255;
inline constexpr int kMaxLevels = 32;

// Why `params` is unusable (nullopt if fine).
std::optional<std::string> ParamsProblem(const VocabularyParams& params);

struct TreeProblem {
  NodeId node = 0;  // offending node id (0: the tree as a whole)
  std::string message;
};
// First inconsistency of a node list (see Vocabulary::FromNodes), or nullopt.
std::optional<TreeProblem> FindTreeProblem(const VocabularyParams& params,
                                           const std::vector<VocabularyNode>& nodes);

// Weight text for the DBoW2 format: "%g" (what C++ streams print by default) when that reads
// back to the same double, else the shortest text that does.
std::string FormatWeight(double weight);

}  // namespace pkslam::bow_internal
