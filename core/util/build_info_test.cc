#include "core/util/build_info.h"

#include <gtest/gtest.h>

#include <regex>

namespace pkslam {
namespace {

// The build records its commit (cmake/PkslamBuildInfo.cmake): 40 hex digits, "-dirty" when
// tracked files differed, or "unknown" outside a git checkout.
TEST(BuildInfo, CommitIsAShaOrUnknown) {
  const std::string commit = BuildCommit();
  EXPECT_TRUE(std::regex_match(commit, std::regex("([0-9a-f]{40}(-dirty)?)|unknown"))) << commit;
}

TEST(BuildInfo, DescriptionNamesVersionCommitAndBuildType) {
  const std::string text = BuildDescription();
  EXPECT_EQ(
      text.rfind(std::string("pkslam ") + PKSLAM_VERSION + " (commit " + BuildCommit() + ", ", 0),
      0u)
      << text;
  EXPECT_EQ(text.back(), ')');
}

}  // namespace
}  // namespace pkslam
