#include "evaluation/statistics.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/util/error.h"

namespace pkslam {

ErrorStatistics ComputeErrorStatistics(std::span<const double> errors) {
  PKSLAM_CHECK(!errors.empty(), "statistics of an empty error array");
  ErrorStatistics s;
  s.count = errors.size();
  const double n = static_cast<double>(errors.size());
  double sum = 0.0;
  for (const double e : errors) {
    sum += e;
    s.sse += e * e;
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(s.sse / n);
  double squared_deviation = 0.0;
  for (const double e : errors) squared_deviation += (e - s.mean) * (e - s.mean);
  s.std = std::sqrt(squared_deviation / n);
  const auto [min_it, max_it] = std::minmax_element(errors.begin(), errors.end());
  s.min = *min_it;
  s.max = *max_it;

  std::vector<double> sorted(errors.begin(), errors.end());
  const std::size_t mid = sorted.size() / 2;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(mid), sorted.end());
  s.median = sorted[mid];
  if (sorted.size() % 2 == 0) {
    // The lower middle value is the largest of the elements before `mid`.
    const double lower =
        *std::max_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(mid));
    s.median = 0.5 * (lower + s.median);
  }
  return s;
}

}  // namespace pkslam
