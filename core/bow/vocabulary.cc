#include "core/bow/vocabulary.h"

#include <fmt/format.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <deque>
#include <fstream>
#include <utility>

#include "core/bow/vocabulary_internal.h"
#include "core/util/error.h"

namespace pkslam {

std::string WeightingName(Weighting weighting) {
  switch (weighting) {
    case Weighting::kTfIdf:
      return "tf-idf";
    case Weighting::kTf:
      return "tf";
    case Weighting::kIdf:
      return "idf";
    case Weighting::kBinary:
      return "binary";
  }
  return fmt::format("unknown({})", static_cast<int>(weighting));
}

std::string ScoringName(Scoring scoring) {
  return scoring == Scoring::kL1 ? "L1" : fmt::format("unknown({})", static_cast<int>(scoring));
}

namespace bow_internal {

std::optional<std::string> ParamsProblem(const VocabularyParams& p) {
  if (p.branching < 2 || p.branching > kMaxBranching) {
    return fmt::format("branching factor k = {} outside [2, {}]", p.branching, kMaxBranching);
  }
  if (p.levels < 1 || p.levels > kMaxLevels) {
    return fmt::format("depth L = {} outside [1, {}]", p.levels, kMaxLevels);
  }
  if (p.scoring != Scoring::kL1) {
    return fmt::format("scoring {} is not supported (pkslam scores with L1 = 0 only)",
                       static_cast<int>(p.scoring));
  }
  const int w = static_cast<int>(p.weighting);
  if (w < 0 || w > 3) return fmt::format("weighting {} outside [0, 3]", w);
  return std::nullopt;
}

std::optional<TreeProblem> FindTreeProblem(const VocabularyParams& params,
                                           const std::vector<VocabularyNode>& nodes) {
  if (nodes.empty()) return TreeProblem{0, "no root node"};
  if (nodes.size() > std::size_t{UINT32_MAX} - 1) return TreeProblem{0, "too many nodes"};
  std::vector<std::uint8_t> level(nodes.size(), 0);
  std::vector<std::uint8_t> has_children(nodes.size(), 0);
  std::size_t words = 0;
  for (std::size_t i = 1; i < nodes.size(); ++i) {
    const NodeId id = static_cast<NodeId>(i);
    const VocabularyNode& n = nodes[i];
    if (n.parent >= id) {
      return TreeProblem{id, fmt::format("parent {} is not an earlier node", n.parent)};
    }
    if (n.parent != 0 && nodes[n.parent].is_leaf) {
      return TreeProblem{id,
                         fmt::format("parent {} is a word (leaf), not an inner node", n.parent)};
    }
    if (!std::isfinite(n.weight)) return TreeProblem{id, "weight is not finite"};
    level[i] = static_cast<std::uint8_t>(level[n.parent] + 1);
    if (level[i] > params.levels) {
      return TreeProblem{id, fmt::format("node at level {} but the vocabulary's depth L is {}",
                                         level[i], params.levels)};
    }
    has_children[n.parent] = 1;
    if (n.is_leaf) ++words;
  }
  for (std::size_t i = 1; i < nodes.size(); ++i) {
    if (!nodes[i].is_leaf && !has_children[i]) {
      return TreeProblem{static_cast<NodeId>(i), "inner node (not a leaf) without children"};
    }
  }
  if (words == 0) return TreeProblem{0, "the vocabulary has no words (leaves)"};
  return std::nullopt;
}

}  // namespace bow_internal

namespace {

// True if the children of every node have consecutive ids.
bool ChildrenContiguous(const std::vector<VocabularyNode>& nodes) {
  std::vector<NodeId> last_child(nodes.size(), 0);
  for (std::size_t i = 1; i < nodes.size(); ++i) {
    NodeId& last = last_child[nodes[i].parent];
    if (last != 0 && last + 1 != i) return false;
    last = static_cast<NodeId>(i);
  }
  return true;
}

// Breadth-first renumbering (children keep their relative order), which makes them contiguous.
std::vector<VocabularyNode> RenumberBreadthFirst(const std::vector<VocabularyNode>& nodes) {
  std::vector<std::vector<NodeId>> children(nodes.size());
  for (std::size_t i = 1; i < nodes.size(); ++i) {
    children[nodes[i].parent].push_back(static_cast<NodeId>(i));
  }
  std::vector<VocabularyNode> out;
  out.reserve(nodes.size());
  out.push_back(nodes[0]);
  std::vector<NodeId> new_id(nodes.size(), 0);
  std::deque<NodeId> queue{0};
  while (!queue.empty()) {
    const NodeId old = queue.front();
    queue.pop_front();
    for (NodeId c : children[old]) {
      new_id[c] = static_cast<NodeId>(out.size());
      VocabularyNode n = nodes[c];
      n.parent = new_id[old];
      out.push_back(n);
      queue.push_back(c);
    }
  }
  return out;
}

// Issues prefetches for the `count` 32-byte descriptors starting at `p`.
inline void PrefetchBlock(const Descriptor* p, std::uint32_t count) {
  const char* begin = reinterpret_cast<const char*>(p);
  const char* end = begin + std::size_t{count} * sizeof(Descriptor);
  for (const char* q = begin; q < end; q += 64) __builtin_prefetch(q);
  __builtin_prefetch(end - 1);
}

// Greedy descent of each descriptor: the hot loop of Transform. The children of a node are one
// contiguous block of 32-byte descriptors; below the top levels every block is a cache miss,
// so descriptors descend in batches, level by level, with each block prefetched for the whole
// batch before any of them is scanned (the misses overlap instead of queueing).
[[gnu::always_inline]] inline void DescendBody(const Descriptor* descriptors, std::size_t count,
                                               const Descriptor* node_descriptors,
                                               const bow_detail::ChildSpan* children, int di_level,
                                               NodeId* leaves, NodeId* di_nodes) {
  constexpr std::size_t kBatch = 16;
  NodeId node[kBatch];
  NodeId di_node[kBatch];
  for (std::size_t base = 0; base < count; base += kBatch) {
    const std::size_t m = std::min(kBatch, count - base);
    for (std::size_t j = 0; j < m; ++j) node[j] = di_node[j] = 0;
    for (int level = 1;; ++level) {
      bool descending = false;
      for (std::size_t j = 0; j < m; ++j) {
        const bow_detail::ChildSpan span = children[node[j]];
        if (span.count != 0) PrefetchBlock(node_descriptors + span.first, span.count);
      }
      for (std::size_t j = 0; j < m; ++j) {
        const bow_detail::ChildSpan span = children[node[j]];
        if (span.count == 0) continue;
        descending = true;
        const Descriptor& d = descriptors[base + j];
        const Descriptor* c = node_descriptors + span.first;
        std::uint32_t best = 0;
        int best_distance = INT_MAX;
        for (std::uint32_t i = 0; i < span.count; ++i) {
          const int dist = HammingDistance(d, c[i]);
          if (dist < best_distance) {
            best_distance = dist;
            best = i;
          }
        }
        node[j] = span.first + best;
        if (level <= di_level) di_node[j] = node[j];
        __builtin_prefetch(children + node[j]);
      }
      if (!descending) break;
    }
    for (std::size_t j = 0; j < m; ++j) {
      leaves[base + j] = node[j];
      if (di_nodes != nullptr) di_nodes[base + j] = di_node[j];
    }
  }
}

PKSLAM_TARGET_POPCNT void DescendPopcnt(const Descriptor* descriptors, std::size_t count,
                                        const Descriptor* node_descriptors,
                                        const bow_detail::ChildSpan* children, int di_level,
                                        NodeId* leaves, NodeId* di_nodes) {
  DescendBody(descriptors, count, node_descriptors, children, di_level, leaves, di_nodes);
}

void DescendBaseline(const Descriptor* descriptors, std::size_t count,
                     const Descriptor* node_descriptors, const bow_detail::ChildSpan* children,
                     int di_level, NodeId* leaves, NodeId* di_nodes) {
  DescendBody(descriptors, count, node_descriptors, children, di_level, leaves, di_nodes);
}

void Descend(const Descriptor* descriptors, std::size_t count, const Descriptor* node_descriptors,
             const bow_detail::ChildSpan* children, int di_level, NodeId* leaves,
             NodeId* di_nodes) {
  (bow_internal::CpuHasPopcnt() ? DescendPopcnt : DescendBaseline)(
      descriptors, count, node_descriptors, children, di_level, leaves, di_nodes);
}

}  // namespace

Vocabulary Vocabulary::FromNodes(const VocabularyParams& params,
                                 std::vector<VocabularyNode> nodes) {
  if (auto problem = bow_internal::ParamsProblem(params)) throw Error("vocabulary: " + *problem);
  if (auto problem = bow_internal::FindTreeProblem(params, nodes)) {
    throw Error(fmt::format("vocabulary node {}: {}", problem->node, problem->message));
  }
  return FromValidNodes(params, std::move(nodes));
}

Vocabulary Vocabulary::FromValidNodes(const VocabularyParams& params,
                                      std::vector<VocabularyNode> nodes) {
  if (!ChildrenContiguous(nodes)) nodes = RenumberBreadthFirst(nodes);
  Vocabulary v;
  v.params_ = params;
  v.BuildArrays(nodes);
  return v;
}

void Vocabulary::BuildArrays(const std::vector<VocabularyNode>& nodes) {
  const std::size_t n = nodes.size();
  descriptors_.resize(n);
  children_.assign(n, ChildSpan{});
  parents_.resize(n);
  weights_.resize(n);
  node_levels_.assign(n, 0);
  node_words_.assign(n, kNoWord);
  word_nodes_.clear();
  parents_[0] = 0;
  descriptors_[0] = nodes[0].descriptor;
  weights_[0] = nodes[0].weight;
  for (std::size_t i = 1; i < n; ++i) {
    const VocabularyNode& node = nodes[i];
    const NodeId id = static_cast<NodeId>(i);
    descriptors_[i] = node.descriptor;
    parents_[i] = node.parent;
    weights_[i] = node.weight;
    node_levels_[i] = static_cast<std::uint8_t>(node_levels_[node.parent] + 1);
    ChildSpan& span = children_[node.parent];
    if (span.count == 0) span.first = id;
    ++span.count;
    if (node.is_leaf) {
      node_words_[i] = static_cast<WordId>(word_nodes_.size());
      word_nodes_.push_back(id);
    }
  }
}

std::vector<VocabularyNode> Vocabulary::Nodes() const {
  std::vector<VocabularyNode> nodes(node_count());
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    nodes[i].parent = parents_[i];
    nodes[i].is_leaf = i != 0 && node_words_[i] != kNoWord;
    nodes[i].descriptor = descriptors_[i];
    nodes[i].weight = weights_[i];
  }
  return nodes;
}

int Vocabulary::depth() const {
  int d = 0;
  for (NodeId node : word_nodes_) d = std::max(d, static_cast<int>(node_levels_[node]));
  return d;
}

std::vector<std::size_t> Vocabulary::NodesPerLevel() const {
  std::vector<std::size_t> count(static_cast<std::size_t>(levels()) + 1, 0);
  for (std::uint8_t l : node_levels_) ++count[l];
  return count;
}

std::vector<std::size_t> Vocabulary::WordsPerLevel() const {
  std::vector<std::size_t> count(static_cast<std::size_t>(levels()) + 1, 0);
  for (NodeId node : word_nodes_) ++count[node_levels_[node]];
  return count;
}

WordId Vocabulary::FindWord(const Descriptor& descriptor) const {
  if (empty()) return kNoWord;
  NodeId leaf = 0;
  Descend(&descriptor, 1, descriptors_.data(), children_.data(), 0, &leaf, nullptr);
  return node_words_[leaf];
}

int Vocabulary::DirectIndexLevel(int levels_from_root) const {
  return std::clamp(levels_from_root, 1, std::max(1, levels()));
}

int Vocabulary::DirectIndexLevelFromLevelsUp(int levels_up) const {
  return DirectIndexLevel(levels() - levels_up);
}

void Vocabulary::Quantize(std::span<const Descriptor> descriptors, int di_level, WordId* words,
                          NodeId* di_nodes) const {
  std::vector<NodeId> leaves(descriptors.size());
  Descend(descriptors.data(), descriptors.size(), descriptors_.data(), children_.data(), di_level,
          leaves.data(), di_nodes);
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    words[i] = weights_[leaves[i]] > 0.0 ? node_words_[leaves[i]] : kNoWord;
  }
}

BowVector Vocabulary::Transform(std::span<const Descriptor> descriptors) const {
  BowVector bow;
  Transform(descriptors, &bow, nullptr);
  return bow;
}

void Vocabulary::Transform(std::span<const Descriptor> descriptors, BowVector* bow,
                           FeatureVector* features, int direct_index_level) const {
  if (empty()) {
    if (bow != nullptr) *bow = BowVector();
    if (features != nullptr) *features = FeatureVector();
    return;
  }
  const std::size_t n = descriptors.size();
  std::vector<WordId> words(n);
  std::vector<NodeId> di_nodes(features != nullptr ? n : 0);
  Quantize(descriptors, DirectIndexLevel(direct_index_level), words.data(),
           features != nullptr ? di_nodes.data() : nullptr);

  if (bow != nullptr) {
    std::vector<BowEntry> entries;
    entries.reserve(n);
    for (WordId w : words) {
      if (w != kNoWord) entries.push_back(BowEntry{w, WordWeight(w)});
    }
    if (weighting() == Weighting::kIdf || weighting() == Weighting::kBinary) {
      // Counted once per image: drop repeats before summing.
      std::sort(entries.begin(), entries.end(),
                [](const BowEntry& a, const BowEntry& b) { return a.word_id < b.word_id; });
      entries.erase(
          std::unique(entries.begin(), entries.end(),
                      [](const BowEntry& a, const BowEntry& b) { return a.word_id == b.word_id; }),
          entries.end());
    }
    *bow = BowVector::FromUnsorted(std::move(entries));
    bow->NormalizeL1();
  }
  if (features != nullptr) {
    std::vector<std::pair<NodeId, std::uint32_t>> pairs;
    pairs.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (words[i] != kNoWord) pairs.emplace_back(di_nodes[i], static_cast<std::uint32_t>(i));
    }
    *features = FeatureVector::FromPairs(std::move(pairs));
  }
}

double Vocabulary::Score(const BowVector& a, const BowVector& b) const { return L1Score(a, b); }

void VocabularyTrainOptions::Check() const {
  PKSLAM_CHECK_OPTION(branching >= 2 && branching <= bow_internal::kMaxBranching, "branching", "{}",
                      branching);
  PKSLAM_CHECK_OPTION(levels >= 1 && levels <= bow_internal::kMaxLevels, "levels", "{}", levels);
  PKSLAM_CHECK_OPTION(static_cast<int>(weighting) >= 0 && static_cast<int>(weighting) <= 3,
                      "weighting", "{}", static_cast<int>(weighting));
  PKSLAM_CHECK_OPTION(max_iterations >= 1, "max_iterations", "{}", max_iterations);
  PKSLAM_CHECK_OPTION(parallel_assign_min >= 1, "parallel_assign_min", "{}", parallel_assign_min);
}

std::uint64_t Vocabulary::Fingerprint() const {
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const void* data, std::size_t n) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
      h ^= bytes[i];
      h *= 1099511628211ull;
    }
  };
  const std::int32_t params[4] = {params_.branching, params_.levels,
                                  static_cast<std::int32_t>(params_.scoring),
                                  static_cast<std::int32_t>(params_.weighting)};
  mix(params, sizeof(params));
  for (const Descriptor& d : descriptors_) mix(d.bytes.data(), d.bytes.size());
  mix(parents_.data(), parents_.size() * sizeof(NodeId));
  mix(weights_.data(), weights_.size() * sizeof(double));
  return h;
}

}  // namespace pkslam
