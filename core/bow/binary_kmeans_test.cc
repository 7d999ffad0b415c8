#include "core/bow/binary_kmeans.h"

#include <gtest/gtest.h>

#include <random>
#include <set>

namespace pkslam::bow_internal {
namespace {

Descriptor RandomDescriptor(std::mt19937_64& rng) {
  Descriptor d;
  for (auto& b : d.bytes) b = static_cast<std::uint8_t>(rng());
  return d;
}

Descriptor FlipBits(Descriptor d, int bits, std::mt19937_64& rng) {
  std::uniform_int_distribution<int> pick(0, 255);
  for (int i = 0; i < bits; ++i) {
    const int bit = pick(rng);
    d.bytes[bit / 8] = static_cast<std::uint8_t>(d.bytes[bit / 8] ^ (1u << (bit % 8)));
  }
  return d;
}

TEST(BitCounter, MajorityVoteByHand) {
  Descriptor a, b, c;
  a.bytes[0] = 0b0000'0111;
  b.bytes[0] = 0b0000'0011;
  c.bytes[0] = 0b0000'0001;
  c.bytes[31] = 0x80;
  // bit 0: 3/3, bit 1: 2/3, bit 2: 1/3, bit 255: 1/3.
  const Descriptor m = MajorityCentre(std::vector<Descriptor>{a, b, c});
  EXPECT_EQ(m.bytes[0], 0b0000'0011);
  EXPECT_EQ(m.bytes[31], 0);
}

TEST(BitCounter, EvenSplitSetsTheBitAsDBoW2) {
  Descriptor a, b;
  a.bytes[5] = 0x10;
  const Descriptor m = MajorityCentre(std::vector<Descriptor>{a, b});
  EXPECT_EQ(m.bytes[5], 0x10);
}

TEST(BitCounter, CountsBeyondLaneCapacity) {
  // 1000 additions pass the 255-per-lane flush several times.
  BitCounter counter;
  Descriptor set;
  set.bytes[3] = 0xFF;
  for (int i = 0; i < 1000; ++i) counter.Add(i < 600 ? set : Descriptor{});
  EXPECT_EQ(counter.total(), 1000u);
  EXPECT_EQ(counter.Count(24), 600u);
  EXPECT_EQ(counter.Count(31), 600u);
  EXPECT_EQ(counter.Count(0), 0u);
  BitCounter other;
  for (int i = 0; i < 300; ++i) other.Add(set);
  counter.Merge(other);
  EXPECT_EQ(counter.Count(24), 900u);
  EXPECT_EQ(counter.Majority().bytes[3], 0xFF);  // 900 of 1300
}

TEST(SplitMix64, BelowStaysInRangeAndIsReproducible) {
  SplitMix64 a(42), b(42);
  for (int i = 0; i < 1000; ++i) {
    const std::uint64_t x = a.Below(7);
    EXPECT_LT(x, 7u);
    EXPECT_EQ(x, b.Below(7));
  }
  EXPECT_NE(ChildSeed(1, 0), ChildSeed(1, 1));
  EXPECT_NE(ChildSeed(1, 0), ChildSeed(2, 0));
}

TEST(ClusterDescriptors, TrivialCaseOneClusterPerDistinctDescriptor) {
  std::mt19937_64 rng(1);
  const Descriptor x = RandomDescriptor(rng), y = RandomDescriptor(rng);
  const std::vector<Descriptor> points = {x, y, x};
  ClusterOptions options;
  options.k = 3;
  const ClusterResult r = ClusterDescriptors(points, options);
  ASSERT_EQ(r.centres.size(), 2u);
  EXPECT_EQ(r.centres[0], x);
  EXPECT_EQ(r.centres[1], y);
  EXPECT_EQ(r.labels, (std::vector<std::uint32_t>{0, 1, 0}));
}

TEST(ClusterDescriptors, RecoversWellSeparatedClusters) {
  std::mt19937_64 rng(7);
  constexpr int kClusters = 5;
  std::vector<Descriptor> prototypes;
  for (int c = 0; c < kClusters; ++c) prototypes.push_back(RandomDescriptor(rng));
  std::vector<Descriptor> points;
  std::vector<int> truth;
  for (int i = 0; i < 2000; ++i) {
    truth.push_back(i % kClusters);
    points.push_back(FlipBits(prototypes[i % kClusters], 12, rng));
  }
  ClusterOptions options;
  options.k = kClusters;
  const ClusterResult r = ClusterDescriptors(points, options);
  ASSERT_EQ(r.centres.size(), static_cast<std::size_t>(kClusters));
  // Each true cluster maps to exactly one label and vice versa.
  std::set<std::pair<int, std::uint32_t>> pairs;
  for (std::size_t i = 0; i < points.size(); ++i) pairs.insert({truth[i], r.labels[i]});
  EXPECT_EQ(pairs.size(), static_cast<std::size_t>(kClusters));
  // Majority centres of 400 noisy copies land on the prototype.
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(r.centres[r.labels[i]], prototypes[truth[i]]);
  }
}

TEST(ClusterDescriptors, LabelsPointToNearestCentre) {
  std::mt19937_64 rng(3);
  std::vector<Descriptor> points;
  for (int i = 0; i < 3000; ++i) points.push_back(RandomDescriptor(rng));
  ClusterOptions options;
  options.k = 8;
  options.max_iterations = 3;  // stopped early: labels must still be the nearest centre
  const ClusterResult r = ClusterDescriptors(points, options);
  ASSERT_GE(r.centres.size(), 2u);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const int own = HammingDistance(points[i], r.centres[r.labels[i]]);
    for (const Descriptor& c : r.centres) EXPECT_LE(own, HammingDistance(points[i], c));
  }
}

TEST(ClusterDescriptors, DeterministicAcrossThreadCounts) {
  std::mt19937_64 rng(11);
  std::vector<Descriptor> points;
  for (int i = 0; i < 20000; ++i) points.push_back(RandomDescriptor(rng));
  ClusterOptions serial;
  serial.k = 10;
  serial.seed = 5;
  const ClusterResult a = ClusterDescriptors(points, serial);
  for (int threads : {2, 3}) {
    ClusterOptions parallel = serial;
    parallel.parallel_min = 1;
    parallel.threads = threads;
    const ClusterResult b = ClusterDescriptors(points, parallel);
    EXPECT_EQ(a.centres, b.centres);
    EXPECT_EQ(a.labels, b.labels);
    EXPECT_EQ(a.iterations, b.iterations);
  }
  serial.seed = 6;
  EXPECT_NE(ClusterDescriptors(points, serial).centres, a.centres);
}

TEST(ClusterDescriptors, IdenticalPointsGiveOneCluster) {
  std::mt19937_64 rng(2);
  const std::vector<Descriptor> points(50, RandomDescriptor(rng));
  ClusterOptions options;
  options.k = 10;
  const ClusterResult r = ClusterDescriptors(points, options);
  EXPECT_EQ(r.centres.size(), 1u);
}

}  // namespace
}  // namespace pkslam::bow_internal
