// Test and benchmark helpers for core/bow: random descriptors and synthetic vocabularies.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "core/bow/vocabulary.h"

namespace pkslam::testing {

inline Descriptor RandomDescriptor(std::mt19937_64& rng) {
  Descriptor d;
  for (auto& b : d.bytes) b = static_cast<std::uint8_t>(rng());
  return d;
}

inline Descriptor FlipBits(Descriptor d, int bits, std::mt19937_64& rng) {
  std::uniform_int_distribution<int> pick(0, 255);
  for (int i = 0; i < bits; ++i) {
    const int bit = pick(rng);
    d.bytes[bit / 8] = static_cast<std::uint8_t>(d.bytes[bit / 8] ^ (1u << (bit % 8)));
  }
  return d;
}

// A full k-ary tree of depth L with random node descriptors and random word weights, numbered
// as DBoW2 numbers trained trees. Only for load/lookup timing and format tests: its words mean
// nothing.
inline Vocabulary MakeRandomVocabulary(int k, int levels, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> weight(0.01, 8.0);
  std::vector<VocabularyNode> nodes(1);
  // Depth-first expansion: children of a node get consecutive ids when it is expanded.
  std::vector<std::pair<NodeId, int>> stack = {{0, 0}};
  while (!stack.empty()) {
    const auto [id, level] = stack.back();
    stack.pop_back();
    const auto first = static_cast<NodeId>(nodes.size());
    for (int c = 0; c < k; ++c) {
      VocabularyNode n;
      n.parent = id;
      n.is_leaf = level + 1 == levels;
      n.descriptor = RandomDescriptor(rng);
      n.weight = n.is_leaf ? weight(rng) : 0.0;
      nodes.push_back(n);
    }
    if (level + 1 < levels) {
      for (int c = k - 1; c >= 0; --c) stack.push_back({first + static_cast<NodeId>(c), level + 1});
    }
  }
  VocabularyParams params;
  params.branching = k;
  params.levels = levels;
  return Vocabulary::FromNodes(params, std::move(nodes));
}

}  // namespace pkslam::testing
