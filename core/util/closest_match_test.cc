#include "core/util/closest_match.h"

#include <gtest/gtest.h>

namespace pkslam {
namespace {

TEST(EditDistance, CountsInsertionsDeletionsAndSubstitutions) {
  EXPECT_EQ(EditDistance("", ""), 0u);
  EXPECT_EQ(EditDistance("stereo", "stereo"), 0u);
  EXPECT_EQ(EditDistance("stero", "stereo"), 1u);
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3u);
  EXPECT_EQ(EditDistance("abc", ""), 3u);
  EXPECT_EQ(EditDistance("Sensor", "sensor"), 0u);  // case does not count
  EXPECT_EQ(EditDistance("mnoo", "mono"), 1u);       // swapped neighbours: one typo
}

TEST(ClosestMatch, SuggestsATypoButNotAnotherWord) {
  const std::vector<std::string> sensors = {"mono", "stereo", "rgbd", "mono-inertial",
                                            "stereo-inertial", "rgbd-inertial"};
  EXPECT_EQ(ClosestMatch("stero", sensors), "stereo");
  EXPECT_EQ(ClosestMatch("stereo-intertial", sensors), "stereo-inertial");
  EXPECT_EQ(ClosestMatch("lidar", sensors), std::nullopt);
  EXPECT_EQ(ClosestMatch("", sensors), std::nullopt);
  EXPECT_EQ(DidYouMean("mnoo", sensors), " (did you mean 'mono'?)");
  EXPECT_EQ(DidYouMean("thermal", sensors), "");
}

TEST(ClosestMatch, AUniquePrefixIsAMatchAnAmbiguousOneIsNot) {
  const std::vector<std::string> flags = {"--dataset", "--deterministic", "--localise-only"};
  EXPECT_EQ(ClosestMatch("--local", flags), "--localise-only");
  EXPECT_EQ(ClosestMatch("--d", flags), std::nullopt);
}

}  // namespace
}  // namespace pkslam
