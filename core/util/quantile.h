// Percentiles of timing samples, computed the same way by `pkslam run` (stats.json), the
// bench's peer import and the benchmarks: the value of nearest rank round(q (n - 1)), so
// q = 0.5 is the upper median of an even count.
#pragma once

#include <algorithm>
#include <cstddef>
#include <optional>
#include <vector>

namespace pkslam {

// std::nullopt for no values.
inline std::optional<double> Quantile(std::vector<double> values, double q) {
  if (values.empty()) return std::nullopt;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1) + 0.5);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

}  // namespace pkslam
