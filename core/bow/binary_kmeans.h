// k-means++ over binary descriptors for one vocabulary node: Hamming distance, cluster centres
// by per-bit majority vote (DBoW2's mean of ORB descriptors). Internal to core/bow training.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/features/descriptor.h"

namespace pkslam::bow_internal {

// Deterministic 64-bit generator (SplitMix64): identical sequences on every platform, unlike
// the standard distributions.
class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
  std::uint64_t Next();
  // Uniform in [0, bound) for bound > 0 (multiply-shift; bias < bound / 2^64).
  std::uint64_t Below(std::uint64_t bound);

 private:
  std::uint64_t state_;
};

// Seed of child `index` of a node with seed `seed` (independent of traversal order).
std::uint64_t ChildSeed(std::uint64_t seed, std::size_t index);

// Per-bit vote counts of a set of descriptors.
class BitCounter {
 public:
  void Add(const Descriptor& d);
  void Merge(const BitCounter& other);
  std::uint32_t total() const { return total_; }
  // Votes for bit i (byte i/8, bit i%8).
  std::uint32_t Count(int bit) const;
  // Bit i set iff at least ceil(total/2) of the descriptors have it (DBoW2's rule: an even
  // split sets the bit). All zero when empty.
  Descriptor Majority() const;

 private:
  void FlushLanes();

  // Byte-wide lane counters (the 8 bits of descriptor byte b in the 8 bytes of lanes_[b]),
  // moved into counts_ every 255 additions, before a lane can overflow.
  std::uint64_t lanes_[32] = {};
  std::uint32_t counts_[256] = {};
  std::uint32_t pending_ = 0;
  std::uint32_t total_ = 0;
};

// Majority-vote centre of `descriptors`.
Descriptor MajorityCentre(std::span<const Descriptor> descriptors);

struct ClusterResult {
  std::vector<Descriptor> centres;    // non-empty clusters only, at most k
  std::vector<std::uint32_t> labels;  // per descriptor: index into centres (its nearest)
  int iterations = 0;                 // Lloyd iterations run
  bool converged = true;              // false if stopped by max_iterations
};

struct ClusterOptions {
  int k = 10;
  int max_iterations = 50;
  std::uint64_t seed = 1;
  std::size_t parallel_min = 50000;  // split assignment across threads above this many points
  int threads = 1;                   // threads for the split steps (>= 1)
};

// Clusters `descriptors` into at most k groups. With n <= k every distinct descriptor is its
// own cluster (DBoW2's trivial case). Otherwise k-means++ seeding (probability proportional
// to squared Hamming distance; fewer than k seeds when fewer distinct points), then Lloyd
// iterations until no label changes or max_iterations. Labels always point to the nearest
// centre (ties: lowest index). Deterministic for a seed, whatever the thread count.
ClusterResult ClusterDescriptors(std::span<const Descriptor> descriptors,
                                 const ClusterOptions& options);

}  // namespace pkslam::bow_internal
