#include "core/bow/vocabulary.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/util/error.h"

namespace pkslam {
namespace {

Descriptor Filled(int first_byte, int end_byte, std::uint8_t value = 0xFF) {
  Descriptor d;
  for (int b = first_byte; b < end_byte; ++b) d.bytes[b] = value;
  return d;
}

VocabularyNode Node(NodeId parent, bool leaf, Descriptor d, double weight = 0.0) {
  return VocabularyNode{parent, leaf, d, weight};
}

// k=2, L=2:           root
//            A(1) = 0x00..           B(2) = 0xFF..
//  a1(3)=0x00.. a2(4)=FF x8,00..  b1(5)=0xFF..  b2(6)=00 x8,FF..
// words 0..3 = nodes 3..6, weights 0.5, 1, 2, 0.
std::vector<VocabularyNode> TinyNodes() {
  return {VocabularyNode{},
          Node(0, false, Filled(0, 0)),
          Node(0, false, Filled(0, 32)),
          Node(1, true, Filled(0, 0), 0.5),
          Node(1, true, Filled(0, 8), 1.0),
          Node(2, true, Filled(0, 32), 2.0),
          Node(2, true, Filled(8, 32), 0.0)};
}

Vocabulary Tiny(Weighting weighting = Weighting::kTfIdf, int levels = 2) {
  VocabularyParams params;
  params.branching = 2;
  params.levels = levels;
  params.weighting = weighting;
  return Vocabulary::FromNodes(params, TinyNodes());
}

const Descriptor kQa1 = Filled(0, 0);   // -> A -> a1 (word 0)
const Descriptor kQa2 = Filled(0, 6);   // 48 bits: A (48 < 208), a2 (16 < 48) (word 1)
const Descriptor kQb1 = Filled(0, 32);  // -> B -> b1 (word 2)
const Descriptor kQb2 = Filled(8, 32);  // 192 bits: B (64 < 192), b2 (0) (word 3, weight 0)

TEST(Vocabulary, Structure) {
  const Vocabulary v = Tiny();
  EXPECT_EQ(v.node_count(), 7u);
  EXPECT_EQ(v.word_count(), 4u);
  EXPECT_EQ(v.depth(), 2);
  EXPECT_EQ(v.first_child(0), 1u);
  EXPECT_EQ(v.child_count(0), 2);
  EXPECT_EQ(v.first_child(2), 5u);
  EXPECT_TRUE(v.is_leaf(4));
  EXPECT_EQ(v.word_of_node(5), 2u);
  EXPECT_EQ(v.word_node(2), 5u);
  EXPECT_EQ(v.word_of_node(1), Vocabulary::kNoWord);
  EXPECT_DOUBLE_EQ(v.WordWeight(1), 1.0);
  EXPECT_EQ(v.level(6), 2);
  EXPECT_EQ(v.NodesPerLevel(), (std::vector<std::size_t>{1, 2, 4}));
  EXPECT_EQ(v.WordsPerLevel(), (std::vector<std::size_t>{0, 0, 4}));
  EXPECT_EQ(v.Nodes(), TinyNodes());
}

TEST(Vocabulary, FindWordDescendsGreedily) {
  const Vocabulary v = Tiny();
  EXPECT_EQ(v.FindWord(kQa1), 0u);
  EXPECT_EQ(v.FindWord(kQa2), 1u);
  EXPECT_EQ(v.FindWord(kQb1), 2u);
  EXPECT_EQ(v.FindWord(kQb2), 3u);
  // 128 bits set: equally far from A and B; the tie goes to the first child (A), then a2.
  EXPECT_EQ(v.FindWord(Filled(0, 16)), 1u);
  EXPECT_EQ(Vocabulary().FindWord(kQa1), Vocabulary::kNoWord);
}

// TF-IDF by hand: a1 twice (2 x 0.5 = 1), b1 once (2), b2 has weight 0 and is dropped:
// normalised (1/3, 2/3).
TEST(Vocabulary, TransformTfIdfByHand) {
  const Vocabulary v = Tiny();
  const std::vector<Descriptor> image = {kQa1, kQb2, kQa1, kQb1};
  BowVector bow;
  FeatureVector fv;
  v.Transform(image, &bow, &fv, 1);
  ASSERT_EQ(bow.size(), 2u);
  EXPECT_DOUBLE_EQ(bow.Weight(0), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(bow.Weight(2), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(bow.Weight(3), 0.0);
  // Direct index at level 1: features 0 and 2 under A (node 1), 3 under B (node 2).
  ASSERT_EQ(fv.size(), 2u);
  EXPECT_EQ(fv.groups()[0], (FeatureGroup{1, {0, 2}}));
  EXPECT_EQ(fv.groups()[1], (FeatureGroup{2, {3}}));
  EXPECT_EQ(v.Transform(image), bow);
}

TEST(Vocabulary, TransformTfSumsIdfAndBinaryCountOnce) {
  const std::vector<Descriptor> image = {kQa1, kQa1, kQb1};
  // TF: 2 x 0.5 and 1 x 2 -> (1/3, 2/3).
  const BowVector tf = Tiny(Weighting::kTf).Transform(image);
  EXPECT_DOUBLE_EQ(tf.Weight(0), 1.0 / 3.0);
  // IDF / binary: each word once -> 0.5 and 2 -> (0.2, 0.8).
  for (Weighting w : {Weighting::kIdf, Weighting::kBinary}) {
    const BowVector once = Tiny(w).Transform(image);
    EXPECT_DOUBLE_EQ(once.Weight(0), 0.2) << WeightingName(w);
    EXPECT_DOUBLE_EQ(once.Weight(2), 0.8) << WeightingName(w);
  }
}

TEST(Vocabulary, FeatureVectorGroupingLevel) {
  const Vocabulary v = Tiny();
  const std::vector<Descriptor> image = {kQa1, kQa2, kQb1, kQa1};
  BowVector bow;
  FeatureVector level1, level2, level0, level9;
  v.Transform(image, &bow, &level1, 1);
  v.Transform(image, &bow, &level2, 2);
  v.Transform(image, &bow, &level0, 0);
  v.Transform(image, &bow, &level9, 9);
  EXPECT_EQ(level1.groups(), (std::vector<FeatureGroup>{{1, {0, 1, 3}}, {2, {2}}}));
  EXPECT_EQ(level2.groups(), (std::vector<FeatureGroup>{{3, {0, 3}}, {4, {1}}, {5, {2}}}));
  // Level 0 would put everything in one group (the root): clamped to level 1. Deeper than
  // L: the words.
  EXPECT_EQ(level0, level1);
  EXPECT_EQ(level9, level2);
}

TEST(Vocabulary, DirectIndexLevelsFromRootAndFromLeaves) {
  // ORB-SLAM's transform(..., 4) on ORBvoc.txt (k=10, L=6) means level 2 from the root.
  EXPECT_EQ(Tiny(Weighting::kTfIdf, 6).DirectIndexLevelFromLevelsUp(4), 2);
  EXPECT_EQ(Tiny(Weighting::kTfIdf, 6).DirectIndexLevel(2), 2);
  // A shallow L=4 vocabulary: DBoW2 would use the root (one group); we stay at level 1.
  EXPECT_EQ(Tiny(Weighting::kTfIdf, 4).DirectIndexLevelFromLevelsUp(4), 1);
  EXPECT_EQ(Tiny(Weighting::kTfIdf, 2).DirectIndexLevel(Vocabulary::kDefaultDirectIndexLevel), 2);
  EXPECT_EQ(Tiny(Weighting::kTfIdf, 2).DirectIndexLevel(5), 2);
  // L = 1: the only level below the root is the words.
  VocabularyParams params;
  params.branching = 2;
  params.levels = 1;
  const Vocabulary flat = Vocabulary::FromNodes(
      params,
      {VocabularyNode{}, Node(0, true, Filled(0, 0), 1.0), Node(0, true, Filled(0, 32), 1.0)});
  EXPECT_EQ(flat.DirectIndexLevelFromLevelsUp(4), 1);
  EXPECT_EQ(flat.DirectIndexLevel(0), 1);
  BowVector bow;
  FeatureVector fv;
  flat.Transform(std::vector<Descriptor>{kQa1, kQb1, kQa1}, &bow, &fv);
  EXPECT_EQ(fv.groups(), (std::vector<FeatureGroup>{{1, {0, 2}}, {2, {1}}}));
}

TEST(Vocabulary, WordShallowerThanDirectIndexLevelGroupsByTheWord) {
  VocabularyParams params;
  params.branching = 2;
  params.levels = 2;
  // root -> leaf W(1) = zeros, inner I(2) = ones -> two leaves.
  const Vocabulary v = Vocabulary::FromNodes(
      params, {VocabularyNode{}, Node(0, true, Filled(0, 0), 1.0), Node(0, false, Filled(0, 32)),
               Node(2, true, Filled(0, 32), 1.0), Node(2, true, Filled(8, 32), 1.0)});
  BowVector bow;
  FeatureVector fv;
  v.Transform(std::vector<Descriptor>{kQa1, kQb1}, &bow, &fv, 2);
  EXPECT_EQ(fv.groups(), (std::vector<FeatureGroup>{{1, {0}}, {3, {1}}}));
}

TEST(Vocabulary, NonContiguousChildrenAreRenumbered) {
  // Children of node 1 are 3 and 5: renumbered breadth-first, lookups unchanged.
  VocabularyParams params;
  params.branching = 2;
  params.levels = 2;
  const Vocabulary v = Vocabulary::FromNodes(
      params, {VocabularyNode{}, Node(0, false, Filled(0, 0)), Node(0, false, Filled(0, 32)),
               Node(1, true, Filled(0, 0), 1.0), Node(2, true, Filled(0, 32), 2.0),
               Node(1, true, Filled(0, 8), 3.0), Node(2, true, Filled(8, 32), 4.0)});
  for (NodeId n = 0; n < v.node_count(); ++n) {
    for (int c = 0; c < v.child_count(n); ++c) EXPECT_EQ(v.parent(v.first_child(n) + c), n);
  }
  EXPECT_DOUBLE_EQ(v.WordWeight(v.FindWord(kQa1)), 1.0);
  EXPECT_DOUBLE_EQ(v.WordWeight(v.FindWord(kQa2)), 3.0);
  EXPECT_DOUBLE_EQ(v.WordWeight(v.FindWord(kQb1)), 2.0);
  EXPECT_DOUBLE_EQ(v.WordWeight(v.FindWord(kQb2)), 4.0);
}

TEST(Vocabulary, RejectsInconsistentTrees) {
  VocabularyParams params;
  params.branching = 2;
  params.levels = 2;
  const auto expect_error = [&](std::vector<VocabularyNode> nodes, const char* what) {
    try {
      Vocabulary::FromNodes(params, std::move(nodes));
      ADD_FAILURE() << "no error for: " << what;
    } catch (const Error& e) {
      EXPECT_THAT(e.what(), ::testing::HasSubstr(what));
    }
  };
  auto nodes = TinyNodes();
  nodes[3].parent = 5;
  expect_error(nodes, "node 3: parent 5 is not an earlier node");
  nodes = TinyNodes();
  nodes[6].parent = 3;
  expect_error(nodes, "node 6: parent 3 is a word");
  nodes = TinyNodes();
  nodes.pop_back();
  nodes.pop_back();  // B keeps no children
  expect_error(nodes, "node 2: inner node (not a leaf) without children");
  nodes = TinyNodes();
  nodes[5].is_leaf = false;
  nodes.push_back(Node(5, true, Filled(0, 0), 1.0));
  expect_error(nodes, "node 7: node at level 3 but the vocabulary's depth L is 2");
  expect_error({VocabularyNode{}}, "no words");
  params.scoring = static_cast<Scoring>(2);
  expect_error(TinyNodes(), "scoring 2 is not supported");
}

TEST(Vocabulary, EmptyVocabularyTransformsToEmptyVectors) {
  const Vocabulary v;
  BowVector bow = BowVector::FromUnsorted({{1, 1.0}});
  FeatureVector fv = FeatureVector::FromPairs({{1, 1}});
  v.Transform(std::vector<Descriptor>{kQa1}, &bow, &fv);
  EXPECT_TRUE(bow.empty());
  EXPECT_TRUE(fv.empty());
}

}  // namespace
}  // namespace pkslam
