// Locating the shared real data (../shared/data beside the checkout, or $PKSLAM_SHARED_DATA)
// and temporary directories for tests. Tests needing shared data skip when it is absent.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace pkslam::testing {

// The shared data root (contains euroc/, evo/) or nullopt.
std::optional<std::filesystem::path> SharedDataDir();

// A fresh empty directory under the system temp dir, unique per call; removed with its contents
// when the test process exits (kept if PKSLAM_KEEP_TEST_DIRS is set).
std::filesystem::path MakeTempDir(const std::string& prefix);

// The whole content of a file ("" when it cannot be read): byte-for-byte comparisons.
std::string ReadFileBytes(const std::filesystem::path& file);

// The built pkslam executable (build/bin/pkslam) for end-to-end CLI tests.
std::filesystem::path PkslamExecutable();

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr interleaved
};
// Runs a shell command, capturing its combined output.
CommandResult RunCommand(const std::string& command);
// Runs the built pkslam executable with `args` (shell-quoted by the caller).
CommandResult RunPkslam(const std::string& args);

// The integer value of the first `"key": N` in a JSON file such as stats.json; -1 when absent.
long long JsonIntField(const std::filesystem::path& file, const std::string& key);

}  // namespace pkslam::testing

// Inside a TEST body: binds `shared` (std::filesystem::path) or skips the test.
#define PKSLAM_REQUIRE_SHARED_DATA(shared)                                           \
  const auto shared##_opt = ::pkslam::testing::SharedDataDir();                      \
  if (!shared##_opt) {                                                               \
    GTEST_SKIP() << "shared data not found (../shared/data or $PKSLAM_SHARED_DATA)"; \
  }                                                                                  \
  const std::filesystem::path shared = *shared##_opt
