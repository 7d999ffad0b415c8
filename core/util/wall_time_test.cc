#include "core/util/wall_time.h"

#include <gtest/gtest.h>

namespace pkslam {
namespace {

TEST(WallMsSince, CountsMillisecondsFromAPastInstant) {
  const auto start = std::chrono::steady_clock::now() - std::chrono::milliseconds(250);
  const double ms = WallMsSince(start);
  EXPECT_GE(ms, 250.0);
  // A later reading of the same instant is not smaller (the steady clock does not go back).
  EXPECT_GE(WallMsSince(start), ms);
}

}  // namespace
}  // namespace pkslam
