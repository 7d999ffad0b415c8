// Helpers shared by the vocabulary's construction, file formats and training (not public API).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/bow/vocabulary.h"

// GCC/Clang on x86-64 without -mpopcnt turn std::popcount into a library call; the Hamming
// hot loops are compiled twice (POPCNT and baseline) and picked at load time by the dynamic
// loader, so the binary stays portable and fast.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__POPCNT__) && \
    !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
#define PKSLAM_POPCNT_CLONES __attribute__((target_clones("popcnt", "default")))
#else
#define PKSLAM_POPCNT_CLONES
#endif

namespace pkslam::bow_internal {

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
