// Reproducible random numbers for the simulator. The engine is std::mt19937_64 (its output
// sequence is fixed by the C++ standard); the distributions are our own, because the std::
// distributions are implementation-defined and would change the bytes between libraries.
#pragma once

#include <array>
#include <cstdint>
#include <random>

namespace pkslam::sim {

// Sequential generator (IMU noise, scene scatter, random trajectories). Not thread-safe: one
// owner per instance; derive independent streams with Rng(DeriveSeed(seed, stream)).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}

  std::uint64_t NextU64() { return engine_(); }
  // Uniform in [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  // Uniform integer in [0, n); n > 0.
  int UniformInt(int n);
  // Standard normal (Marsaglia polar method, second value cached).
  double Normal();
  double Normal(double mean, double sigma) { return mean + sigma * Normal(); }

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

// Mixes a seed with a stream/counter value (SplitMix64 finaliser): independent sub-seeds for
// "IMU", "scene", "camera 0 frame 17 row 3", ... so parallel work stays reproducible.
std::uint64_t DeriveSeed(std::uint64_t seed, std::uint64_t stream);

// Per-pixel Gaussian noise without per-thread state: a counter-based hash indexes a table of
// standard-normal quantiles. Deterministic regardless of how rows are split across threads.
class PixelNoise {
 public:
  PixelNoise();
  // A standard-normal sample for (key, index); key mixes seed/frame/camera, index the pixel.
  float Sample(std::uint64_t key, std::uint64_t index) const {
    const std::uint64_t h = DeriveSeed(key, index);
    return table_[h >> (64 - kTableBits)];
  }

 private:
  static constexpr int kTableBits = 14;
  std::array<float, 1 << kTableBits> table_{};
};

}  // namespace pkslam::sim
