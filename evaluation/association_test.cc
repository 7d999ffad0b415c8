#include "evaluation/association.h"

#include <gtest/gtest.h>

#include <cmath>
#include <ostream>

#include "core/util/error.h"

namespace pkslam {

void PrintTo(const IndexPair& pair, std::ostream* os) {
  *os << "(ref " << pair.ref << ", est " << pair.est << ")";
}

namespace {

constexpr std::int64_t kMs = 1000000;
constexpr std::int64_t kSecond = 1000 * kMs;

std::vector<IndexPair> Associate(const std::vector<std::int64_t>& ref,
                                 const std::vector<std::int64_t>& est,
                                 AssociationOptions options = AssociationOptions()) {
  return AssociateTimestamps(ref, est, options);
}

TEST(AssociateTimestamps, PairsEachEstimateStampWithTheNearestReferenceStamp) {
  std::vector<std::int64_t> ref;  // 200 Hz from t = 1 s
  for (int k = 0; k < 200; ++k) ref.push_back(1000 * kMs + k * 5 * kMs);
  std::vector<std::int64_t>
      est;  // 20 Hz, each 3 ms after one reference stamp, 2 ms before the next
  for (int k = 0; k < 15; ++k) est.push_back(1003 * kMs + k * 50 * kMs);
  const std::vector<IndexPair> pairs = Associate(ref, est);
  ASSERT_EQ(pairs.size(), 15u);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    EXPECT_EQ(pairs[k].est, k);
    EXPECT_EQ(pairs[k].ref, 10 * k + 1);
  }
}

TEST(AssociateTimestamps, MaxDiffIsInclusiveAndCompared) {
  // |0.010 - 0.000| is exactly 0.01 in double precision: accepted, like evo's <=.
  EXPECT_EQ(Associate({0, 100 * kMs}, {10 * kMs}).size(), 1u);
  EXPECT_TRUE(Associate({0, 100 * kMs}, {10 * kMs + 1}).empty());
  AssociationOptions wide;
  wide.max_diff_s = 0.02;
  EXPECT_EQ(Associate({0, 100 * kMs}, {15 * kMs}, wide).size(), 1u);
  AssociationOptions exact;
  exact.max_diff_s = 0.0;
  EXPECT_EQ(Associate({0, 5 * kMs}, {5 * kMs}, exact), (std::vector<IndexPair>{{1, 0}}));
}

TEST(AssociateTimestamps, TiesGoToTheEarlierStamp) {
  // 5 ms is exactly halfway between 0 and 10 ms (also in double precision).
  EXPECT_EQ(Associate({0, 10 * kMs, 20 * kMs}, {5 * kMs}), (std::vector<IndexPair>{{0, 0}}));
}

TEST(AssociateTimestamps, NoOverlapGivesNoPairs) {
  EXPECT_TRUE(Associate({0, 1 * kMs, 2 * kMs}, {1000 * kMs, 1001 * kMs}).empty());
  EXPECT_TRUE(Associate({}, {1, 2}).empty());
  EXPECT_TRUE(Associate({1, 2}, {}).empty());
}

TEST(AssociateTimestamps, ShorterTrajectoryDrives) {
  // Reference shorter: each reference stamp finds its nearest estimate stamp.
  const std::vector<std::int64_t> ref = {100 * kMs, 200 * kMs};
  const std::vector<std::int64_t> est = {90 * kMs, 98 * kMs, 104 * kMs, 150 * kMs, 201 * kMs};
  EXPECT_EQ(Associate(ref, est), (std::vector<IndexPair>{{0, 1}, {1, 4}}));
  // Equally long: the estimate drives, so (in evo's mode) both estimate stamps take the one
  // reference stamp near them; a reference-driven search would give a single pair.
  AssociationOptions evo;
  evo.one_to_one = false;
  EXPECT_EQ(Associate({0, 96 * kMs}, {98 * kMs, 99 * kMs}, evo),
            (std::vector<IndexPair>{{1, 0}, {1, 1}}));
}

TEST(AssociateTimestamps, OneToOneKeepsTheClosestOfRepeatedMatches) {
  const std::vector<std::int64_t> ref = {0, 100 * kMs, 200 * kMs, 300 * kMs};
  const std::vector<std::int64_t> est = {96 * kMs, 99 * kMs, 205 * kMs};
  AssociationOptions evo;
  evo.one_to_one = false;
  EXPECT_EQ(Associate(ref, est, evo), (std::vector<IndexPair>{{1, 0}, {1, 1}, {2, 2}}));
  EXPECT_EQ(Associate(ref, est), (std::vector<IndexPair>{{1, 1}, {2, 2}}));
  // Equal distances (exact in binary: 125 ms +- 2^-8 s): the earlier estimate pose stays.
  const std::vector<std::int64_t> binary_ref = {0, 125000000, 250000000, 375000000};
  EXPECT_EQ(Associate(binary_ref, {125000000 - 3906250, 125000000 + 3906250, 250000000}),
            (std::vector<IndexPair>{{1, 0}, {2, 2}}));
}

TEST(AssociateTimestamps, OffsetShiftsTheEstimateClock) {
  const std::vector<std::int64_t> ref = {1000 * kMs, 1050 * kMs, 1100 * kMs, 1150 * kMs};
  const std::vector<std::int64_t> est = {3050 * kMs, 3100 * kMs};  // 2 s late
  EXPECT_TRUE(Associate(ref, est).empty());
  AssociationOptions shifted;
  shifted.offset_s = -2.0;
  EXPECT_EQ(Associate(ref, est, shifted), (std::vector<IndexPair>{{1, 0}, {2, 1}}));
  // Same when the estimate is the longer trajectory (the offset then moves the other side).
  const std::vector<std::int64_t> long_est = {3000 * kMs, 3049 * kMs, 3101 * kMs, 3150 * kMs,
                                              3200 * kMs};
  EXPECT_EQ(Associate({1050 * kMs, 1100 * kMs}, long_est, shifted),
            (std::vector<IndexPair>{{0, 1}, {1, 2}}));
}

TEST(AssociateTimestamps, RejectsBadOptionsAndUnsortedInput) {
  AssociationOptions bad;
  bad.max_diff_s = -0.01;
  EXPECT_THROW(Associate({0}, {0}, bad), OptionError);
  bad = AssociationOptions();
  bad.offset_s = std::nan("");
  EXPECT_THROW(Associate({0}, {0}, bad), OptionError);
  EXPECT_THROW(Associate({0, 2, 1}, {0}), Error);
  EXPECT_THROW(Associate({0}, {3, 1}), Error);
}

TEST(AssociateTimestamps, RepeatedEstimateStampsEachPairAsInEvo) {
  // The estimate (3 poses) drives: both poses at 1 s pair with the reference pose at 1 s, also
  // with one_to_one (evo keeps both). Reference 0..9 s.
  std::vector<std::int64_t> ref;
  for (int i = 0; i < 10; ++i) ref.push_back(i * kSecond);
  const std::vector<std::int64_t> est = {kSecond, kSecond, 2 * kSecond};
  const std::vector<IndexPair> expected = {{1, 0}, {1, 1}, {2, 2}};
  EXPECT_EQ(Associate(ref, est), expected);
  AssociationOptions evo;
  evo.one_to_one = false;
  EXPECT_EQ(Associate(ref, est, evo), expected);
  // A repeated stamp in the longer trajectory: the nearest-time search takes the first.
  EXPECT_EQ(Associate({0, kSecond, kSecond, 2 * kSecond}, {kSecond}),
            (std::vector<IndexPair>{{1, 0}}));
}

}  // namespace
}  // namespace pkslam
