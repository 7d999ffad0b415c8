#include "bench/executor.h"

#include <gtest/gtest.h>

#include <fstream>

#include "bench/matrix.h"
#include "bench/suite.h"
#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

TEST(SimCacheDir, DependsOnTheRecipeAndTheSimulatorBuild) {
  HarnessOptions options;
  options.cache = "/cache";
  SimRecipe recipe;
  recipe.motion = "medium";
  recipe.seed = 3;
  options.simulator_id = "build-a";
  const fs::path a = SimCacheDir(options, "flight", recipe);
  EXPECT_EQ(a.parent_path(), fs::path("/cache"));
  EXPECT_EQ(a.filename().string().rfind("flight-seed3-", 0), 0u) << a;
  EXPECT_EQ(SimCacheDir(options, "flight", recipe), a);  // stable

  HarnessOptions rebuilt = options;
  rebuilt.simulator_id = "build-b";
  EXPECT_NE(SimCacheDir(rebuilt, "flight", recipe), a);  // a new build never reuses old renders

  SimRecipe other = recipe;
  other.extra_args = {"--realism", "ideal"};
  EXPECT_NE(SimCacheDir(options, "flight", other), a);
}

TEST(ExecutableId, HashesTheContentAndNamesAnUnreadableFile) {
  const fs::path dir = testing::MakeTempDir("executable_id");
  const auto write = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(dir / name, std::ios::binary) << bytes;
    return dir / name;
  };
  const fs::path a = write("a", std::string("binary\0one", 10));
  const fs::path b = write("b", std::string("binary\0two", 10));
  const fs::path c = write("c", std::string("binary\0one", 10));
  EXPECT_NE(ExecutableId(a), ExecutableId(b));
  EXPECT_EQ(ExecutableId(a), ExecutableId(c));
  EXPECT_EQ(ExecutableId(a).size(), 16u);
  try {
    ExecutableId(dir / "missing");
    FAIL() << "no error for a missing executable";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos) << e.what();
  }
}

// A peer that cannot be started fails its own run (with the reason), not the whole bench.
TEST(ExecuteRun, APeerThatCannotStartIsAFailedRun) {
  const fs::path dir = testing::MakeTempDir("peer_cannot_start");
  fs::create_directories(dir / "data");
  const Suite suite = ParseSuite(
      "runs: 1\nsensors: [stereo]\nselectors: []\npeers:\n"
      "  - {label: p, command: [" +
          (dir / "no_such_peer").string() +
          ", '{dataset}']}\ndatasets:\n  - {name: a, path: " + (dir / "data").string() + "}\n",
      dir / "suite.yaml");
  const auto runs = ExpandSuite(suite);
  ASSERT_EQ(runs.size(), 1u);
  HarnessOptions options;
  options.pkslam = "/bin/true";
  options.out = dir / "out";
  options.cache = dir / "cache";
  const auto result = ExecuteRun(suite, runs[0], options, nullptr);
  ASSERT_TRUE(result.has_value());
  EXPECT_FALSE(result->ok);
  EXPECT_NE(result->error.find("no_such_peer"), std::string::npos) << result->error;
  EXPECT_TRUE(fs::exists(RunDir(options.out, runs[0]) / "result.csv"));
}

}  // namespace
}  // namespace pkslam::bench
