#include "core/bow/bow_vector.h"

#include <algorithm>
#include <cmath>

namespace pkslam {

BowVector BowVector::FromUnsorted(std::vector<BowEntry> entries) {
  std::sort(entries.begin(), entries.end(),
            [](const BowEntry& a, const BowEntry& b) { return a.word_id < b.word_id; });
  BowVector v;
  v.entries_.reserve(entries.size());
  for (const BowEntry& e : entries) {
    if (!v.entries_.empty() && v.entries_.back().word_id == e.word_id) {
      v.entries_.back().weight += e.weight;
    } else {
      v.entries_.push_back(e);
    }
  }
  return v;
}

double BowVector::Weight(WordId word_id) const {
  const auto it = std::lower_bound(entries_.begin(), entries_.end(), word_id,
                                   [](const BowEntry& e, WordId id) { return e.word_id < id; });
  return (it != entries_.end() && it->word_id == word_id) ? it->weight : 0.0;
}

double BowVector::L1Norm() const {
  double norm = 0.0;
  for (const BowEntry& e : entries_) norm += std::abs(e.weight);
  return norm;
}

void BowVector::NormalizeL1() {
  const double norm = L1Norm();
  if (norm <= 0.0) return;
  for (BowEntry& e : entries_) e.weight /= norm;
}

double L1Score(const BowVector& a, const BowVector& b) {
  const double norm_a = a.L1Norm();
  const double norm_b = b.L1Norm();
  if (norm_a <= 0.0 || norm_b <= 0.0) return 0.0;
  const double inv_a = 1.0 / norm_a;
  const double inv_b = 1.0 / norm_b;
  double score = 0.0;
  auto ia = a.begin();
  auto ib = b.begin();
  while (ia != a.end() && ib != b.end()) {
    if (ia->word_id < ib->word_id) {
      ++ia;
    } else if (ib->word_id < ia->word_id) {
      ++ib;
    } else {
      score += std::min(std::abs(ia->weight) * inv_a, std::abs(ib->weight) * inv_b);
      ++ia;
      ++ib;
    }
  }
  // Rounding can push the sum of minima a hair above 1 for identical vectors.
  return std::clamp(score, 0.0, 1.0);
}

FeatureVector FeatureVector::FromPairs(std::vector<std::pair<NodeId, std::uint32_t>> pairs) {
  std::sort(pairs.begin(), pairs.end());
  FeatureVector fv;
  for (const auto& [node_id, feature] : pairs) {
    if (fv.groups_.empty() || fv.groups_.back().node_id != node_id) {
      fv.groups_.push_back(FeatureGroup{node_id, {}});
    }
    auto& features = fv.groups_.back().features;
    if (features.empty() || features.back() != feature) features.push_back(feature);
  }
  return fv;
}

const FeatureGroup* FeatureVector::Find(NodeId node_id) const {
  const auto it = std::lower_bound(groups_.begin(), groups_.end(), node_id,
                                   [](const FeatureGroup& g, NodeId id) { return g.node_id < id; });
  return (it != groups_.end() && it->node_id == node_id) ? &*it : nullptr;
}

std::size_t FeatureVector::FeatureCount() const {
  std::size_t n = 0;
  for (const FeatureGroup& g : groups_) n += g.features.size();
  return n;
}

}  // namespace pkslam
