#include "core/bow/binary_kmeans.h"

#include <algorithm>
#include <array>
#include <climits>
#include <functional>

#include "core/bow/parallel.h"
#include "core/bow/vocabulary_internal.h"
#include "core/util/error.h"

namespace pkslam::bow_internal {
namespace {

// kByteLanes[v]: bit j of v moved to the lowest bit of byte j.
constexpr std::array<std::uint64_t, 256> MakeByteLanes() {
  std::array<std::uint64_t, 256> lanes{};
  for (unsigned v = 0; v < 256; ++v) {
    std::uint64_t x = 0;
    for (unsigned j = 0; j < 8; ++j) x |= std::uint64_t{(v >> j) & 1u} << (8 * j);
    lanes[v] = x;
  }
  return lanes;
}
constexpr std::array<std::uint64_t, 256> kByteLanes = MakeByteLanes();

// Nearest centre of each point in [begin, end); returns how many labels changed.
[[gnu::always_inline]] inline std::size_t AssignRangeBody(const Descriptor* points,
                                                          std::size_t begin, std::size_t end,
                                                          const Descriptor* centres, std::size_t k,
                                                          std::uint32_t* labels) {
  std::size_t changed = 0;
  for (std::size_t i = begin; i < end; ++i) {
    std::uint32_t best = 0;
    int best_distance = INT_MAX;
    for (std::size_t j = 0; j < k; ++j) {
      const int dist = HammingDistance(points[i], centres[j]);
      if (dist < best_distance) {
        best_distance = dist;
        best = static_cast<std::uint32_t>(j);
      }
    }
    if (labels[i] != best) {
      labels[i] = best;
      ++changed;
    }
  }
  return changed;
}

PKSLAM_TARGET_POPCNT std::size_t AssignRangePopcnt(const Descriptor* points, std::size_t begin,
                                                   std::size_t end, const Descriptor* centres,
                                                   std::size_t k, std::uint32_t* labels) {
  return AssignRangeBody(points, begin, end, centres, k, labels);
}
std::size_t AssignRangeBaseline(const Descriptor* points, std::size_t begin, std::size_t end,
                                const Descriptor* centres, std::size_t k, std::uint32_t* labels) {
  return AssignRangeBody(points, begin, end, centres, k, labels);
}
std::size_t AssignRange(const Descriptor* points, std::size_t begin, std::size_t end,
                        const Descriptor* centres, std::size_t k, std::uint32_t* labels) {
  return (CpuHasPopcnt() ? AssignRangePopcnt : AssignRangeBaseline)(points, begin, end, centres, k,
                                                                    labels);
}

// min_d2[i] = min(min_d2[i], d(points[i], centre)^2) over [begin, end); returns their sum.
[[gnu::always_inline]] inline std::uint64_t UpdateMinDistancesBody(const Descriptor* points,
                                                                   std::size_t begin,
                                                                   std::size_t end,
                                                                   const Descriptor& centre,
                                                                   std::uint64_t* min_d2) {
  std::uint64_t sum = 0;
  for (std::size_t i = begin; i < end; ++i) {
    const auto d = static_cast<std::uint64_t>(HammingDistance(points[i], centre));
    min_d2[i] = std::min(min_d2[i], d * d);
    sum += min_d2[i];
  }
  return sum;
}
PKSLAM_TARGET_POPCNT std::uint64_t UpdateMinDistancesPopcnt(const Descriptor* points,
                                                            std::size_t begin, std::size_t end,
                                                            const Descriptor& centre,
                                                            std::uint64_t* min_d2) {
  return UpdateMinDistancesBody(points, begin, end, centre, min_d2);
}
std::uint64_t UpdateMinDistancesBaseline(const Descriptor* points, std::size_t begin,
                                         std::size_t end, const Descriptor& centre,
                                         std::uint64_t* min_d2) {
  return UpdateMinDistancesBody(points, begin, end, centre, min_d2);
}
std::uint64_t UpdateMinDistances(const Descriptor* points, std::size_t begin, std::size_t end,
                                 const Descriptor& centre, std::uint64_t* min_d2) {
  return (CpuHasPopcnt() ? UpdateMinDistancesPopcnt : UpdateMinDistancesBaseline)(
      points, begin, end, centre, min_d2);
}

// Splits [0, n) into contiguous chunks, one task each: serial below options.parallel_min
// points or with one thread.
std::size_t ChunkCount(std::size_t n, const ClusterOptions& options) {
  if (options.threads <= 1 || n < options.parallel_min) return 1;
  return std::min<std::size_t>(n, static_cast<std::size_t>(options.threads) * 4);
}
std::size_t ChunkBegin(std::size_t chunk, std::size_t chunks, std::size_t n) {
  return chunk * n / chunks;
}

// Sum over chunks of f(begin, end). Integer addition is exact, so the result does not depend
// on the chunking or the thread count.
template <typename T>
T SumOverRange(std::size_t n, const ClusterOptions& options,
               const std::function<T(std::size_t, std::size_t)>& f) {
  const std::size_t chunks = ChunkCount(n, options);
  if (chunks == 1) return f(0, n);
  std::vector<T> partial(chunks, T{0});
  ParallelFor(chunks, options.threads, [&](std::size_t c) {
    partial[c] = f(ChunkBegin(c, chunks, n), ChunkBegin(c + 1, chunks, n));
  });
  T sum{0};
  for (T x : partial) sum += x;
  return sum;
}

std::vector<BitCounter> CountBits(std::span<const Descriptor> points,
                                  const std::vector<std::uint32_t>& labels, std::size_t k,
                                  const ClusterOptions& options) {
  const std::size_t n = points.size();
  const std::size_t chunks = ChunkCount(n, options);
  std::vector<std::vector<BitCounter>> partial(chunks, std::vector<BitCounter>(k));
  ParallelFor(chunks, options.threads, [&](std::size_t c) {
    for (std::size_t i = ChunkBegin(c, chunks, n); i < ChunkBegin(c + 1, chunks, n); ++i) {
      partial[c][labels[i]].Add(points[i]);
    }
  });
  for (std::size_t c = 1; c < chunks; ++c) {
    for (std::size_t j = 0; j < k; ++j) partial[0][j].Merge(partial[c][j]);
  }
  return std::move(partial[0]);
}

// k-means++ seeds: the first uniformly, each next with probability ~ squared distance to the
// nearest seed so far.
std::vector<Descriptor> SeedCentres(std::span<const Descriptor> points,
                                    const ClusterOptions& options) {
  const std::size_t n = points.size();
  SplitMix64 rng(options.seed);
  std::vector<Descriptor> centres;
  centres.push_back(points[rng.Below(n)]);
  std::vector<std::uint64_t> min_d2(n, UINT64_MAX);
  while (centres.size() < static_cast<std::size_t>(options.k)) {
    const Descriptor& newest = centres.back();
    const std::uint64_t total =
        SumOverRange<std::uint64_t>(n, options, [&](std::size_t begin, std::size_t end) {
          return UpdateMinDistances(points.data(), begin, end, newest, min_d2.data());
        });
    if (total == 0) break;  // every point coincides with a seed
    const std::uint64_t target = rng.Below(total);
    std::uint64_t cumulative = 0;
    std::size_t pick = n - 1;
    for (std::size_t i = 0; i < n; ++i) {
      cumulative += min_d2[i];
      if (cumulative > target) {
        pick = i;
        break;
      }
    }
    centres.push_back(points[pick]);
  }
  return centres;
}

// Drops empty clusters and renumbers labels accordingly.
void CompactClusters(ClusterResult* result) {
  std::vector<std::uint32_t> members(result->centres.size(), 0);
  for (std::uint32_t l : result->labels) ++members[l];
  std::vector<std::uint32_t> new_index(result->centres.size(), 0);
  std::vector<Descriptor> kept;
  for (std::size_t j = 0; j < members.size(); ++j) {
    new_index[j] = static_cast<std::uint32_t>(kept.size());
    if (members[j] > 0) kept.push_back(result->centres[j]);
  }
  if (kept.size() == result->centres.size()) return;
  for (std::uint32_t& l : result->labels) l = new_index[l];
  result->centres = std::move(kept);
}

}  // namespace

std::uint64_t SplitMix64::Next() {
  std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

std::uint64_t SplitMix64::Below(std::uint64_t bound) {
  PKSLAM_CHECK(bound > 0, "empty range");
  return static_cast<std::uint64_t>((static_cast<unsigned __int128>(Next()) * bound) >> 64);
}

std::uint64_t ChildSeed(std::uint64_t seed, std::size_t index) {
  SplitMix64 mix(seed ^ (0xd1b54a32d192ed03ULL * (index + 1)));
  return mix.Next();
}

void BitCounter::Add(const Descriptor& d) {
  for (int b = 0; b < 32; ++b) lanes_[b] += kByteLanes[d.bytes[b]];
  ++total_;
  if (++pending_ == 255) FlushLanes();
}

void BitCounter::FlushLanes() {
  for (int b = 0; b < 32; ++b) {
    for (int j = 0; j < 8; ++j) counts_[8 * b + j] += (lanes_[b] >> (8 * j)) & 0xFF;
    lanes_[b] = 0;
  }
  pending_ = 0;
}

std::uint32_t BitCounter::Count(int bit) const {
  return counts_[bit] + static_cast<std::uint32_t>((lanes_[bit / 8] >> (8 * (bit % 8))) & 0xFF);
}

void BitCounter::Merge(const BitCounter& other) {
  for (int bit = 0; bit < 256; ++bit) counts_[bit] += other.Count(bit);
  total_ += other.total_;
}

Descriptor BitCounter::Majority() const {
  Descriptor centre;
  if (total_ == 0) return centre;
  const std::uint32_t half_up = total_ / 2 + total_ % 2;
  for (int bit = 0; bit < 256; ++bit) {
    if (Count(bit) >= half_up) {
      centre.bytes[bit / 8] = static_cast<std::uint8_t>(centre.bytes[bit / 8] | (1u << (bit % 8)));
    }
  }
  return centre;
}

Descriptor MajorityCentre(std::span<const Descriptor> descriptors) {
  BitCounter counter;
  for (const Descriptor& d : descriptors) counter.Add(d);
  return counter.Majority();
}

ClusterResult ClusterDescriptors(std::span<const Descriptor> points,
                                 const ClusterOptions& options) {
  PKSLAM_CHECK(options.k >= 1 && options.max_iterations >= 1 && options.threads >= 1,
               "k {} iterations {} threads {}", options.k, options.max_iterations, options.threads);
  ClusterResult result;
  const std::size_t n = points.size();
  if (n == 0) return result;
  result.labels.resize(n);
  if (n <= static_cast<std::size_t>(options.k)) {
    // One cluster per distinct descriptor, in order of first appearance.
    for (std::size_t i = 0; i < n; ++i) {
      const auto it = std::find(result.centres.begin(), result.centres.end(), points[i]);
      result.labels[i] = static_cast<std::uint32_t>(it - result.centres.begin());
      if (it == result.centres.end()) result.centres.push_back(points[i]);
    }
    return result;
  }

  result.centres = SeedCentres(points, options);
  const std::size_t k = result.centres.size();
  std::fill(result.labels.begin(), result.labels.end(), UINT32_MAX);
  const auto assign = [&] {
    return SumOverRange<std::size_t>(n, options, [&](std::size_t b, std::size_t e) {
      return AssignRange(points.data(), b, e, result.centres.data(), k, result.labels.data());
    });
  };
  assign();
  result.converged = false;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    ++result.iterations;
    const std::vector<BitCounter> counters = CountBits(points, result.labels, k, options);
    for (std::size_t j = 0; j < k; ++j) {
      // An empty cluster keeps its centre (it may win points back next round).
      if (counters[j].total() > 0) result.centres[j] = counters[j].Majority();
    }
    if (assign() == 0) {
      result.converged = true;
      break;
    }
  }
  CompactClusters(&result);
  return result;
}

}  // namespace pkslam::bow_internal
