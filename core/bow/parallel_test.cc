#include "core/bow/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <vector>

namespace pkslam::bow_internal {
namespace {

TEST(ParallelFor, CallsEveryIndexOnce) {
  for (int threads : {1, 2, 4}) {
    std::vector<std::atomic<int>> calls(1000);
    ParallelFor(calls.size(), threads, [&](std::size_t i) { ++calls[i]; });
    for (const auto& c : calls) EXPECT_EQ(c.load(), 1) << threads;
  }
  ParallelFor(0, 2, [](std::size_t) { FAIL(); });
}

TEST(ParallelFor, RethrowsTheLowestFailingIndex) {
  try {
    ParallelFor(100, 3, [](std::size_t i) {
      if (i == 40 || i == 41 || i == 90) throw std::runtime_error(std::to_string(i));
    });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    // Indices are handed out in order, so 40 is always reached before a later one fails.
    EXPECT_EQ(std::string(e.what()), "40");
  }
}

TEST(ParallelFor, ResolveThreadCount) {
  EXPECT_EQ(ResolveThreadCount(3), 3);
  EXPECT_GE(ResolveThreadCount(0), 1);
}

}  // namespace
}  // namespace pkslam::bow_internal
