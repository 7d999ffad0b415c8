#include "core/bow/bow_vector.h"

#include <gtest/gtest.h>

namespace pkslam {
namespace {

BowVector Make(std::vector<BowEntry> entries) {
  return BowVector::FromUnsorted(std::move(entries));
}

TEST(BowVector, FromUnsortedSortsAndSumsRepeats) {
  const BowVector v = Make({{7, 1.0}, {2, 0.5}, {7, 2.0}, {4, 0.25}});
  ASSERT_EQ(v.size(), 3u);
  EXPECT_EQ(v.entries()[0], (BowEntry{2, 0.5}));
  EXPECT_EQ(v.entries()[1], (BowEntry{4, 0.25}));
  EXPECT_EQ(v.entries()[2], (BowEntry{7, 3.0}));
  EXPECT_DOUBLE_EQ(v.Weight(7), 3.0);
  EXPECT_DOUBLE_EQ(v.Weight(5), 0.0);
  EXPECT_DOUBLE_EQ(v.L1Norm(), 3.75);
}

TEST(BowVector, NormalizeL1) {
  BowVector v = Make({{1, 1.0}, {3, 3.0}});
  v.NormalizeL1();
  EXPECT_DOUBLE_EQ(v.Weight(1), 0.25);
  EXPECT_DOUBLE_EQ(v.Weight(3), 0.75);
  BowVector empty;
  empty.NormalizeL1();
  EXPECT_TRUE(empty.empty());
}

// Worked by hand: a = (w1 .5, w2 .5), b = (w2 .25, w3 .75).
// |a - b|_1 = .5 + .25 + .75 = 1.5, so s = 1 - 1.5 / 2 = 0.25.
TEST(L1Score, HandWorkedExample) {
  const BowVector a = Make({{1, 0.5}, {2, 0.5}});
  const BowVector b = Make({{2, 0.25}, {3, 0.75}});
  EXPECT_NEAR(L1Score(a, b), 0.25, 1e-15);
  EXPECT_NEAR(L1Score(b, a), 0.25, 1e-15);
}

// a = (w1 .2, w2 .3, w5 .5), b = (w1 .4, w5 .1, w7 .5):
// |a - b|_1 = .2 + .3 + .4 + .5 = 1.4, s = 0.3.
TEST(L1Score, SecondHandWorkedExample) {
  const BowVector a = Make({{1, 0.2}, {2, 0.3}, {5, 0.5}});
  const BowVector b = Make({{1, 0.4}, {5, 0.1}, {7, 0.5}});
  EXPECT_NEAR(L1Score(a, b), 0.3, 1e-15);
}

TEST(L1Score, NormalisesItsInputs) {
  // Same directions as the first example, scaled by 4 and 10.
  const BowVector a = Make({{1, 2.0}, {2, 2.0}});
  const BowVector b = Make({{2, 2.5}, {3, 7.5}});
  EXPECT_NEAR(L1Score(a, b), 0.25, 1e-15);
}

TEST(L1Score, IdenticalIsOneDisjointIsZeroEmptyIsZero) {
  const BowVector a = Make({{1, 0.1}, {4, 0.7}, {9, 0.2}});
  const BowVector b = Make({{2, 0.5}, {3, 0.5}});
  EXPECT_DOUBLE_EQ(L1Score(a, a), 1.0);
  EXPECT_DOUBLE_EQ(L1Score(a, b), 0.0);
  EXPECT_DOUBLE_EQ(L1Score(a, BowVector()), 0.0);
  EXPECT_DOUBLE_EQ(L1Score(BowVector(), BowVector()), 0.0);
}

TEST(FeatureVector, GroupsByNodeWithAscendingFeatures) {
  const FeatureVector fv = FeatureVector::FromPairs({{5, 3}, {2, 7}, {5, 1}, {2, 0}, {9, 4}});
  ASSERT_EQ(fv.size(), 3u);
  EXPECT_EQ(fv.groups()[0], (FeatureGroup{2, {0, 7}}));
  EXPECT_EQ(fv.groups()[1], (FeatureGroup{5, {1, 3}}));
  EXPECT_EQ(fv.groups()[2], (FeatureGroup{9, {4}}));
  EXPECT_EQ(fv.FeatureCount(), 5u);
  ASSERT_NE(fv.Find(5), nullptr);
  EXPECT_EQ(fv.Find(5)->features, (std::vector<std::uint32_t>{1, 3}));
  EXPECT_EQ(fv.Find(3), nullptr);
}

}  // namespace
}  // namespace pkslam
