// Hierarchical vocabulary of binary (ORB) words, in the DBoW2 manner: a k-ary tree of
// cluster centres over 256-bit descriptors (Hamming distance), whose leaves are the words.
// A descriptor is quantised by greedy descent (nearest child at each level); an image becomes
// a TF-IDF weighted, L1-normalised BowVector, compared with DBoW2's L1 score.
//
// Files: DBoW2's ORBvoc.txt text format (vocabulary_text_io.cc) and a compact binary format
// of our own (vocabulary_binary_io.cc). Training: hierarchical k-means++ (vocabulary_train.cc).
//
// Thread safety: a Vocabulary is immutable after construction; all const member functions may
// be called concurrently (the keyframe database and tracking share one instance).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "core/bow/bow_vector.h"
#include "core/features/descriptor.h"

namespace pkslam {

namespace bow_detail {
// Children of a node: ids first .. first + count - 1 (count 0 for a leaf).
struct ChildSpan {
  NodeId first = 0;
  std::uint32_t count = 0;
};
}  // namespace bow_detail

// DBoW2's enumerations, with the numeric values used in the text header.
enum class Weighting : int {
  kTfIdf = 0,   // word weight idf = log(N / n_i); an image's count of a word multiplies it
  kTf = 1,      // word weight 1; counts multiply it
  kIdf = 2,     // word weight idf; counted once per image
  kBinary = 3,  // word weight 1; counted once per image
};
// Only L1 scoring is implemented (DBoW2's L1_NORM = 0, what ORB-SLAM uses); files declaring
// another scoring are rejected rather than scored wrongly.
enum class Scoring : int { kL1 = 0 };

std::string WeightingName(Weighting weighting);
std::string ScoringName(Scoring scoring);

// True if `file` starts with pkslam's binary vocabulary magic (false if unreadable).
bool IsBinaryVocabularyFile(const std::filesystem::path& file);

// Tree shape and scoring, as in the first line of a DBoW2 text file.
struct VocabularyParams {
  int branching = 10;  // k: maximum children per node
  int levels = 6;      // L: maximum depth (root at level 0, deepest words at level L)
  Scoring scoring = Scoring::kL1;
  Weighting weighting = Weighting::kTfIdf;

  friend bool operator==(const VocabularyParams&, const VocabularyParams&) = default;
};

// One node as stored in files. Node ids are implicit: the position in the node list.
struct VocabularyNode {
  NodeId parent = 0;
  bool is_leaf = false;
  Descriptor descriptor;
  double weight = 0.0;  // the word's weight for leaves; 0 (unused) for inner nodes

  friend bool operator==(const VocabularyNode&, const VocabularyNode&) = default;
};

struct VocabularyTrainOptions {
  // Branching factor k (children per node).
  int branching = 10;
  // Depth L (levels below the root).
  int levels = 6;
  // Word weighting learnt from the training images (IDF for kTfIdf / kIdf).
  Weighting weighting = Weighting::kTfIdf;
  // Cap on Lloyd iterations per node (k-means stops earlier when no assignment changes).
  int max_iterations = 50;
  // Seed of the k-means++ seeding; equal seeds and inputs give bit-identical vocabularies
  // whatever the thread count.
  std::uint64_t seed = 1;
  // Nodes with more descriptors than this split their assignment step across threads.
  std::size_t parallel_assign_min = 50000;
  // Worker threads (0 = one per hardware thread). The result does not depend on it.
  int threads = 0;
  // No progress bar.
  bool quiet = false;

  void Check() const;
};

class Vocabulary {
 public:
  static constexpr WordId kNoWord = std::numeric_limits<WordId>::max();
  // Direct-index level counted from the root: 2 is what ORB-SLAM's "4 levels up" means for a
  // k=10, L=6 vocabulary (ORBvoc.txt), independent of the depth of the vocabulary.
  static constexpr int kDefaultDirectIndexLevel = 2;

  // An empty vocabulary (no words); Transform yields empty vectors.
  Vocabulary() = default;

  // From a node list: nodes[0] is the root (only its presence matters), nodes[i].parent < i.
  // Children of a node must be listed contiguously for fast lookup; lists that are not
  // (never produced by DBoW2 or pkslam) are renumbered breadth-first. Throws Error naming
  // the node when the tree is inconsistent (see vocabulary.cc: ValidateNodes).
  static Vocabulary FromNodes(const VocabularyParams& params, std::vector<VocabularyNode> nodes);

  // Loads either format, recognised by content (our binary magic, else DBoW2 text).
  // Throws InputError naming the file and line (text) or byte offset (binary).
  static Vocabulary Load(const std::filesystem::path& file);
  static Vocabulary LoadText(const std::filesystem::path& file);
  static Vocabulary LoadBinary(const std::filesystem::path& file);
  // Saves by extension: .txt -> DBoW2 text; .bin or .pkvoc -> binary. OptionError otherwise.
  void Save(const std::filesystem::path& file) const;
  // DBoW2 text, written the way DBoW2 writes it (weights as C++ streams print doubles, unless
  // that loses precision: then the shortest text that reads back exactly). A file written by
  // DBoW2 or by us round-trips byte for byte through LoadText/SaveText and through binary.
  void SaveText(const std::filesystem::path& file) const;
  void SaveBinary(const std::filesystem::path& file) const;

  // Hierarchical k-means++ over all descriptors, then word weights from the per-image
  // document frequencies. `images[i]` are the descriptors of training image i.
  static Vocabulary Train(const std::vector<std::vector<Descriptor>>& images,
                          const VocabularyTrainOptions& options);

  const VocabularyParams& params() const { return params_; }
  int branching() const { return params_.branching; }
  int levels() const { return params_.levels; }
  Scoring scoring() const { return params_.scoring; }
  Weighting weighting() const { return params_.weighting; }
  std::size_t node_count() const { return descriptors_.size(); }
  std::size_t word_count() const { return word_nodes_.size(); }
  bool empty() const { return word_nodes_.empty(); }

  NodeId parent(NodeId node) const { return parents_[node]; }
  bool is_leaf(NodeId node) const { return children_[node].count == 0; }
  const Descriptor& descriptor(NodeId node) const { return descriptors_[node]; }
  double node_weight(NodeId node) const { return weights_[node]; }
  int level(NodeId node) const { return node_levels_[node]; }
  // Children of `node` are the ids first_child(node) .. first_child(node) + child_count - 1.
  NodeId first_child(NodeId node) const { return children_[node].first; }
  int child_count(NodeId node) const { return static_cast<int>(children_[node].count); }
  // Word of a leaf node, kNoWord for inner nodes.
  WordId word_of_node(NodeId node) const { return node_words_[node]; }
  NodeId word_node(WordId word) const { return word_nodes_[word]; }
  double WordWeight(WordId word) const { return weights_[word_nodes_[word]]; }
  // 64-bit FNV-1a hash of the tree (parameters, node descriptors, parents, weights): map
  // files record it, so a map is only loaded with the vocabulary its BoW vectors came from.
  std::uint64_t Fingerprint() const;
  // The node list as stored in files (inverse of FromNodes).
  std::vector<VocabularyNode> Nodes() const;
  // Deepest level of any word (<= levels()).
  int depth() const;
  // Number of nodes / words at each level 0..levels().
  std::vector<std::size_t> NodesPerLevel() const;
  std::vector<std::size_t> WordsPerLevel() const;

  // The word `descriptor` falls into (greedy descent; ties go to the first child).
  // kNoWord for an empty vocabulary.
  WordId FindWord(const Descriptor& descriptor) const;
  // The direct-index level actually used for a requested level counted from the root:
  // clamped to [1, levels()], so that the index never collapses to the root (one group)
  // even for a shallow vocabulary. For L = 1 that is the words themselves.
  int DirectIndexLevel(int levels_from_root) const;
  // DBoW2 / ORB-SLAM compatibility: the level for DBoW2's `levelsup` (counted from the
  // leaves, i.e. levels() - levels_up), clamped the same way. For k=10, L=6, levels_up=4
  // gives 2; for an L=4 vocabulary DBoW2 would use the root, we use level 1.
  int DirectIndexLevelFromLevelsUp(int levels_up) const;

  // BoW vector of one image's descriptors (weighted per weighting(), L1-normalised).
  BowVector Transform(std::span<const Descriptor> descriptors) const;
  // Also the feature vector: feature i is grouped under the node its descent passes at
  // DirectIndexLevel(direct_index_level) (or its word, when the word is shallower). As in
  // DBoW2, features whose word weight is 0 (seen in every training image) are left out of
  // both vectors.
  void Transform(std::span<const Descriptor> descriptors, BowVector* bow, FeatureVector* features,
                 int direct_index_level = kDefaultDirectIndexLevel) const;
  // Similarity of two BoW vectors in [0, 1] (L1Score).
  double Score(const BowVector& a, const BowVector& b) const;

 private:
  using ChildSpan = bow_detail::ChildSpan;

  // FromNodes for a node list that already passed FindTreeProblem (the loaders check it
  // themselves to report file lines and offsets).
  static Vocabulary FromValidNodes(const VocabularyParams& params,
                                   std::vector<VocabularyNode> nodes);
  // Lays out validated nodes (children contiguous) into the lookup arrays.
  void BuildArrays(const std::vector<VocabularyNode>& nodes);
  // Quantises descriptors: word (kNoWord if its weight is 0) and direct-index node each.
  void Quantize(std::span<const Descriptor> descriptors, int di_level, WordId* words,
                NodeId* di_nodes) const;

  VocabularyParams params_;
  // Per node, indexed by node id; children of a node have consecutive ids, so the descent
  // reads their descriptors from one contiguous block.
  std::vector<Descriptor> descriptors_;
  std::vector<ChildSpan> children_;
  std::vector<NodeId> parents_;
  std::vector<double> weights_;
  std::vector<std::uint8_t> node_levels_;
  std::vector<WordId> node_words_;
  // Per word: its leaf node (words numbered in node-id order, as DBoW2 does).
  std::vector<NodeId> word_nodes_;
};

}  // namespace pkslam
