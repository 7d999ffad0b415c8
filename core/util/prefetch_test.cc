#include "core/util/prefetch.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

namespace pkslam {
namespace {

TEST(Prefetcher, HandsOutEveryItemInOrderThenNothing) {
  Prefetcher<int> prefetcher(
      50, [](std::size_t i) { return static_cast<int>(i) * 3; }, 2);
  std::vector<int> got;
  while (auto item = prefetcher.Next()) got.push_back(*item);
  ASSERT_EQ(got.size(), 50u);
  for (int i = 0; i < 50; ++i) EXPECT_EQ(got[i], 3 * i);
  EXPECT_FALSE(prefetcher.Next().has_value());
}

TEST(Prefetcher, LoadsAheadButNoMoreThanItsDepth) {
  std::atomic<int> loaded{0};
  Prefetcher<int> prefetcher(
      20,
      [&](std::size_t i) {
        ++loaded;
        return static_cast<int>(i);
      },
      3);
  // Without any Next() the loader fills the queue (3) and waits.
  for (int k = 0; k < 200 && loaded.load() < 3; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(loaded.load(), 3);
  EXPECT_EQ(*prefetcher.Next(), 0);
}

TEST(Prefetcher, RethrowsTheLoadErrorAtItsPlace) {
  Prefetcher<int> prefetcher(
      10,
      [](std::size_t i) {
        if (i == 4) throw std::runtime_error("item 4 is corrupt");
        return static_cast<int>(i);
      },
      2);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(*prefetcher.Next(), i);
  EXPECT_THROW(prefetcher.Next(), std::runtime_error);
  EXPECT_FALSE(prefetcher.Next().has_value());
}

TEST(Prefetcher, DestroyedEarlyStopsLoading) {
  std::atomic<int> loaded{0};
  {
    Prefetcher<int> prefetcher(
        1000,
        [&](std::size_t i) {
          ++loaded;
          return static_cast<int>(i);
        },
        2);
    EXPECT_EQ(*prefetcher.Next(), 0);
  }
  EXPECT_LE(loaded.load(), 4);
}

}  // namespace
}  // namespace pkslam
