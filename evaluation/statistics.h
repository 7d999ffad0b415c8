// Summary statistics of an error array, with evo's definitions (numpy semantics):
// rmse = sqrt(mean(e^2)), sse = sum(e^2), median = middle value (mean of the two middle
// values for an even count), std = population standard deviation (numpy's default ddof=0).
#pragma once

#include <cstddef>
#include <span>

namespace pkslam {

struct ErrorStatistics {
  std::size_t count = 0;
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double std = 0.0;
  double min = 0.0;
  double max = 0.0;
  double sse = 0.0;
};

// Throws pkslam::Error for an empty array.
ErrorStatistics ComputeErrorStatistics(std::span<const double> errors);

}  // namespace pkslam
