#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/bow/bow_test_utils.h"
#include "core/bow/vocabulary.h"
#include "core/util/error.h"

namespace pkslam {
namespace {

using pkslam::testing::FlipBits;
using pkslam::testing::RandomDescriptor;

// Four prototypes pairwise 128 bits apart.
std::vector<Descriptor> Prototypes() {
  Descriptor p0, p1, p2, p3;
  for (int b = 0; b < 16; ++b) p1.bytes[b] = 0xFF;
  for (int b = 0; b < 8; ++b) p2.bytes[b] = p2.bytes[16 + b] = 0xFF;
  for (int b = 8; b < 24; ++b) p3.bytes[b] = 0xFF;
  return {p0, p1, p2, p3};
}

VocabularyTrainOptions Quiet(int k, int levels) {
  VocabularyTrainOptions options;
  options.branching = k;
  options.levels = levels;
  options.quiet = true;
  return options;
}

// IDF by hand: P0 is in all 4 images (idf log 1 = 0), P1 in 2 (log 2), P2 and P3 in one
// each (log 4).
TEST(VocabularyTrain, IdfFromDocumentFrequencies) {
  const auto p = Prototypes();
  const std::vector<std::vector<Descriptor>> images = {
      {p[0], p[1]}, {p[0], p[2]}, {p[0], p[3], p[3]}, {p[0], p[1]}};
  const Vocabulary v = Vocabulary::Train(images, Quiet(4, 1));
  ASSERT_EQ(v.word_count(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(v.descriptor(v.word_node(v.FindWord(p[i]))), p[i]);  // exact clusters
  }
  EXPECT_DOUBLE_EQ(v.WordWeight(v.FindWord(p[0])), 0.0);
  EXPECT_DOUBLE_EQ(v.WordWeight(v.FindWord(p[1])), std::log(2.0));
  EXPECT_DOUBLE_EQ(v.WordWeight(v.FindWord(p[2])), std::log(4.0));
  EXPECT_DOUBLE_EQ(v.WordWeight(v.FindWord(p[3])), std::log(4.0));
  // Image 2: P0 (weight 0) drops out; P3 twice -> the only word.
  const BowVector bow = v.Transform(images[2]);
  ASSERT_EQ(bow.size(), 1u);
  EXPECT_DOUBLE_EQ(bow.Weight(v.FindWord(p[3])), 1.0);
  // Image 0 vs 3 identical -> 1; image 1 vs 2 share only the zero-weight P0 -> 0.
  EXPECT_DOUBLE_EQ(v.Score(v.Transform(images[0]), v.Transform(images[3])), 1.0);
  EXPECT_DOUBLE_EQ(v.Score(v.Transform(images[1]), v.Transform(images[2])), 0.0);
}

TEST(VocabularyTrain, TfAndBinaryWeightsAreOne) {
  const auto p = Prototypes();
  const std::vector<std::vector<Descriptor>> images = {{p[0], p[1]}, {p[0], p[2], p[3]}};
  auto options = Quiet(4, 1);
  options.weighting = Weighting::kBinary;
  const Vocabulary v = Vocabulary::Train(images, options);
  EXPECT_EQ(v.weighting(), Weighting::kBinary);
  for (WordId w = 0; w < v.word_count(); ++w) EXPECT_EQ(v.WordWeight(w), 1.0);
}

std::vector<std::vector<Descriptor>> NoisyImages(int n_images, int per_image, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Descriptor> prototypes;
  for (int i = 0; i < 300; ++i) prototypes.push_back(RandomDescriptor(rng));
  std::vector<std::vector<Descriptor>> images(n_images);
  std::uniform_int_distribution<int> pick(0, 299);
  for (auto& image : images) {
    for (int i = 0; i < per_image; ++i) image.push_back(FlipBits(prototypes[pick(rng)], 20, rng));
  }
  return images;
}

TEST(VocabularyTrain, TreeShapeRespectsKAndL) {
  const auto images = NoisyImages(20, 300, 1);
  const Vocabulary v = Vocabulary::Train(images, Quiet(5, 3));
  EXPECT_EQ(v.branching(), 5);
  EXPECT_EQ(v.levels(), 3);
  EXPECT_LE(v.depth(), 3);
  EXPECT_GT(v.word_count(), 25u);
  EXPECT_LE(v.word_count(), 125u);
  for (NodeId n = 0; n < v.node_count(); ++n) {
    EXPECT_LE(v.child_count(n), 5);
    EXPECT_EQ(v.is_leaf(n), n != 0 && v.word_of_node(n) != Vocabulary::kNoWord);
  }
  // Idf weights are log(N / n_i) with 1 <= n_i <= N.
  for (WordId w = 0; w < v.word_count(); ++w) {
    EXPECT_GE(v.WordWeight(w), 0.0);
    EXPECT_LE(v.WordWeight(w), std::log(20.0) + 1e-12);
  }
}

// Reference descent written against the public accessors: nearest child at every level.
NodeId ReferenceLeaf(const Vocabulary& v, const Descriptor& d) {
  NodeId node = 0;
  while (!v.is_leaf(node)) {
    NodeId best = v.first_child(node);
    for (int c = 1; c < v.child_count(node); ++c) {
      const NodeId child = v.first_child(node) + static_cast<NodeId>(c);
      if (HammingDistance(d, v.descriptor(child)) < HammingDistance(d, v.descriptor(best))) {
        best = child;
      }
    }
    node = best;
  }
  return node;
}

// Transform puts every training descriptor in the leaf reached by choosing the nearest centre
// along the path, and groups it under that path's level-2 node.
TEST(VocabularyTrain, TransformFollowsNearestCentresAlongThePath) {
  const auto images = NoisyImages(10, 200, 2);
  const Vocabulary v = Vocabulary::Train(images, Quiet(4, 4));
  for (const auto& image : images) {
    BowVector bow;
    FeatureVector fv;
    v.Transform(image, &bow, &fv, 2);
    std::vector<NodeId> group_of(image.size(), Vocabulary::kNoWord);
    for (const FeatureGroup& g : fv) {
      for (std::uint32_t f : g.features) group_of[f] = g.node_id;
    }
    for (std::size_t i = 0; i < image.size(); ++i) {
      const NodeId leaf = ReferenceLeaf(v, image[i]);
      ASSERT_EQ(v.FindWord(image[i]), v.word_of_node(leaf));
      if (v.WordWeight(v.word_of_node(leaf)) <= 0.0) continue;  // left out, as in DBoW2
      EXPECT_GT(bow.Weight(v.word_of_node(leaf)), 0.0);
      NodeId ancestor = leaf;
      while (v.level(ancestor) > 2) ancestor = v.parent(ancestor);
      EXPECT_EQ(group_of[i], ancestor);
    }
  }
}

TEST(VocabularyTrain, DeterministicForSeedAndThreadCount) {
  const auto images = NoisyImages(30, 400, 3);
  auto options = Quiet(6, 3);
  options.parallel_assign_min = 1000;  // exercise the split assignment too
  options.threads = 1;
  const Vocabulary a = Vocabulary::Train(images, options);
  for (int threads : {2, 3}) {
    options.threads = threads;
    EXPECT_EQ(Vocabulary::Train(images, options).Nodes(), a.Nodes()) << threads << " threads";
  }
  options.seed = 2;
  EXPECT_NE(Vocabulary::Train(images, options).Nodes(), a.Nodes());
}

// Descriptor sets, not hand-made vectors: the same set scores 1; sets drawn from disjoint
// prototype pools score near 0; two sets from the same pool in between.
TEST(VocabularyTrain, IdenticalSetsScoreOneDisjointNearZero) {
  std::mt19937_64 rng(4);
  std::vector<Descriptor> pool_a, pool_b;
  for (int i = 0; i < 100; ++i) pool_a.push_back(RandomDescriptor(rng));
  for (int i = 0; i < 100; ++i) pool_b.push_back(RandomDescriptor(rng));
  const auto draw = [&](const std::vector<Descriptor>& pool) {
    std::vector<Descriptor> image;
    for (int i = 0; i < 300; ++i) image.push_back(FlipBits(pool[rng() % pool.size()], 15, rng));
    return image;
  };
  std::vector<std::vector<Descriptor>> images;
  for (int i = 0; i < 10; ++i) images.push_back(draw(i % 2 == 0 ? pool_a : pool_b));
  const Vocabulary v = Vocabulary::Train(images, Quiet(10, 3));
  const BowVector a1 = v.Transform(draw(pool_a));
  const BowVector a2 = v.Transform(draw(pool_a));
  const BowVector b1 = v.Transform(draw(pool_b));
  EXPECT_NEAR(v.Score(a1, a1), 1.0, 1e-12);
  EXPECT_LT(v.Score(a1, b1), 0.05);
  EXPECT_GT(v.Score(a1, a2), 0.2);
}

TEST(VocabularyTrain, IdenticalDescriptorsGiveOneWord) {
  const Descriptor d = Prototypes()[1];
  const Vocabulary v = Vocabulary::Train({{d, d, d}, {d}}, Quiet(10, 6));
  EXPECT_EQ(v.word_count(), 1u);
  EXPECT_EQ(v.FindWord(d), 0u);
}

TEST(VocabularyTrain, RejectsBadOptionsAndNoData) {
  EXPECT_THROW(Vocabulary::Train({{Descriptor{}}}, Quiet(1, 3)), OptionError);
  EXPECT_THROW(Vocabulary::Train({{Descriptor{}}}, Quiet(10, 0)), OptionError);
  EXPECT_THROW(Vocabulary::Train({{}, {}}, Quiet(10, 2)), Error);
}

}  // namespace
}  // namespace pkslam
