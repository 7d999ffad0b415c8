#include "sim/random.h"

#include <cmath>

#include "core/util/error.h"

namespace pkslam::sim {

int Rng::UniformInt(int n) {
  PKSLAM_CHECK(n > 0, "UniformInt needs n > 0, got {}", n);
  // Rejection keeps the distribution exactly uniform.
  const std::uint64_t range = static_cast<std::uint64_t>(n);
  const std::uint64_t limit = UINT64_MAX - UINT64_MAX % range;
  std::uint64_t x = engine_();
  while (x >= limit) x = engine_();
  return static_cast<int>(x % range);
}

double Rng::Normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u = 0.0;
  double v = 0.0;
  double s = 0.0;
  do {
    u = 2.0 * Uniform() - 1.0;
    v = 2.0 * Uniform() - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double factor = std::sqrt(-2.0 * std::log(s) / s);
  spare_ = v * factor;
  has_spare_ = true;
  return u * factor;
}

std::uint64_t DeriveSeed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (stream + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

namespace {

// Inverse of the standard normal CDF by bisection on erfc (run once per table entry).
double NormalQuantile(double p) {
  double lo = -10.0;
  double hi = 10.0;
  for (int i = 0; i < 80; ++i) {
    const double mid = 0.5 * (lo + hi);
    const double cdf = 0.5 * std::erfc(-mid / std::sqrt(2.0));
    (cdf < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

PixelNoise::PixelNoise() {
  const int n = static_cast<int>(table_.size());
  double sum_sq = 0.0;
  for (int i = 0; i < n; ++i) {
    table_[i] = static_cast<float>(NormalQuantile((i + 0.5) / n));
    sum_sq += static_cast<double>(table_[i]) * table_[i];
  }
  // The mid-point quantiles have a variance slightly below 1; rescale so sigma is exact.
  const float scale = static_cast<float>(1.0 / std::sqrt(sum_sq / n));
  for (float& v : table_) v *= scale;
}

}  // namespace pkslam::sim
