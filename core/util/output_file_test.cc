#include "core/util/output_file.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <fstream>
#include <iterator>

#include "core/util/error.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

std::string Slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

fs::path FreshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("pkslam_output_file_{}", name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

int FilesIn(const fs::path& dir) {
  return static_cast<int>(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

TEST(WriteFileAtomically, ReplacesTheFileAndLeavesNoTemporary) {
  const fs::path dir = FreshDir("replace");
  WriteFileAtomically(dir / "a.txt", "first version, longer\n");
  WriteFileAtomically(dir / "a.txt", "second\n");
  EXPECT_EQ(Slurp(dir / "a.txt"), "second\n");
  EXPECT_EQ(FilesIn(dir), 1);
}

TEST(WriteFileAtomically, MissingDirectoryIsAnOutputErrorNamingTheFile) {
  const fs::path file = FreshDir("missing") / "no" / "such" / "dir.txt";
  try {
    WriteFileAtomically(file, "x");
    FAIL() << "no error";
  } catch (const OutputError& e) {
    EXPECT_EQ(e.file(), file);
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("No such file"), std::string::npos) << e.what();
  }
}

// Exits 0 when writing 100 kB under a 4 kB file-size limit fails with an OutputError naming the
// file and the reason.
[[noreturn]] void OverwriteBeyondFileSizeLimit(const fs::path& file) {
  std::signal(SIGXFSZ, SIG_IGN);
  rlimit limit{4096, 4096};
  setrlimit(RLIMIT_FSIZE, &limit);
  try {
    WriteFileAtomically(file, std::string(100000, 'x'));
  } catch (const OutputError& e) {
    const std::string what = e.what();
    const bool named = what.find(file.string()) != std::string::npos;
    std::_Exit(named && what.find("too large") != std::string::npos ? 0 : 3);
  }
  std::_Exit(4);
}

// A full disk in miniature: with RLIMIT_FSIZE the write fails part-way (EFBIG). The earlier
// complete version must survive and no temporary may stay behind. In a child process, because
// the limit and the ignored SIGXFSZ are process-wide.
TEST(WriteFileAtomicallyDeathTest, FailedWriteKeepsTheEarlierFileIntact) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const fs::path dir = FreshDir("efbig");
  WriteFileAtomically(dir / "traj.txt", "complete\n");
  EXPECT_EXIT(OverwriteBeyondFileSizeLimit(dir / "traj.txt"), ::testing::ExitedWithCode(0), "");
  EXPECT_EQ(Slurp(dir / "traj.txt"), "complete\n");
  EXPECT_EQ(FilesIn(dir), 1);
}

TEST(OutputFile, NothingIsWrittenWithoutCommit) {
  const fs::path dir = FreshDir("commit");
  {
    OutputFile f(dir / "b.txt");
    f.stream() << "abandoned";
  }
  EXPECT_FALSE(fs::exists(dir / "b.txt"));
  OutputFile f(dir / "b.txt");
  f.stream() << "kept " << 42;
  f.Commit();
  EXPECT_EQ(Slurp(dir / "b.txt"), "kept 42");
}

TEST(AppendFile, AppendsWholeLinesAndRemembersTheFirstFailure) {
  const fs::path dir = FreshDir("append");
  {
    AppendFile f(dir / "p.txt");
    ASSERT_TRUE(f.ok()) << f.error();
    f.Append("1 2\n");
    f.Append("3 4\n");
  }
  EXPECT_EQ(Slurp(dir / "p.txt"), "1 2\n3 4\n");
  AppendFile bad(dir / "missing" / "p.txt");
  EXPECT_FALSE(bad.ok());
  bad.Append("dropped\n");  // no crash, no throw
  EXPECT_NE(bad.error().find("No such file"), std::string::npos) << bad.error();
}

}  // namespace
}  // namespace pkslam
