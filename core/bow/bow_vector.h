// Bag-of-words vectors of an image: the BowVector (word -> weight, for place recognition) and
// the FeatureVector (vocabulary node -> the image's features below it, the "direct index" used
// to restrict descriptor matching to features that share a node).
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace pkslam {

// Word ids number the leaves of a vocabulary 0..word_count-1; node ids number all of its nodes
// (root 0). Both are dense indices into the vocabulary's arrays.
using WordId = std::uint32_t;
using NodeId = std::uint32_t;

struct BowEntry {
  WordId word_id = 0;
  double weight = 0.0;

  friend bool operator==(const BowEntry&, const BowEntry&) = default;
};

// Sparse vector sorted by strictly increasing word id (so two vectors are compared by one
// merge in O(nnz)). Weights are non-negative.
class BowVector {
 public:
  BowVector() = default;

  // From entries in any order; entries with equal word ids are summed.
  static BowVector FromUnsorted(std::vector<BowEntry> entries);

  const std::vector<BowEntry>& entries() const { return entries_; }
  std::size_t size() const { return entries_.size(); }
  bool empty() const { return entries_.empty(); }
  auto begin() const { return entries_.begin(); }
  auto end() const { return entries_.end(); }

  // Weight of `word_id` (binary search), 0 if absent.
  double Weight(WordId word_id) const;
  // Sum of |weight|.
  double L1Norm() const;
  // Scales so that L1Norm() == 1 (no-op on an empty or all-zero vector).
  void NormalizeL1();

  friend bool operator==(const BowVector&, const BowVector&) = default;

 private:
  std::vector<BowEntry> entries_;
};

// DBoW2's L1 score of two BoW vectors: s = 1 - 0.5 * | a/|a|_1 - b/|b|_1 |_1, in [0, 1]
// (1 for proportional vectors, 0 for vectors without a common word). Either vector may be
// unnormalised. Since weights are non-negative this equals the sum over common words of
// min(a_i/|a|, b_i/|b|), computed in one merge, O(nnz(a) + nnz(b)). Empty vectors score 0.
double L1Score(const BowVector& a, const BowVector& b);

// Features of one image grouped by the vocabulary node they pass through at the direct-index
// level: sorted by strictly increasing node id; each group's feature indices ascend.
struct FeatureGroup {
  NodeId node_id = 0;
  std::vector<std::uint32_t> features;

  friend bool operator==(const FeatureGroup&, const FeatureGroup&) = default;
};

class FeatureVector {
 public:
  FeatureVector() = default;

  // From (node id, feature index) pairs in any order.
  static FeatureVector FromPairs(std::vector<std::pair<NodeId, std::uint32_t>> pairs);

  const std::vector<FeatureGroup>& groups() const { return groups_; }
  std::size_t size() const { return groups_.size(); }
  bool empty() const { return groups_.empty(); }
  auto begin() const { return groups_.begin(); }
  auto end() const { return groups_.end(); }

  // The group of `node_id` (binary search) or nullptr.
  const FeatureGroup* Find(NodeId node_id) const;
  // Total number of feature indices over all groups.
  std::size_t FeatureCount() const;

  friend bool operator==(const FeatureVector&, const FeatureVector&) = default;

 private:
  std::vector<FeatureGroup> groups_;
};

}  // namespace pkslam
