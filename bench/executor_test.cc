#include "bench/executor.h"

#include <gtest/gtest.h>

#include <fstream>

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

}  // namespace
}  // namespace pkslam::bench
