#include "bench/process.h"

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <future>
#include <sstream>
#include <thread>

#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

std::string Read(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(RunProcess, CapturesOutputAndExitCode) {
  const fs::path dir = testing::MakeTempDir("bench_process");
  const ProcessResult ok =
      RunProcess({"/bin/sh", "-c", "echo out; echo err >&2"}, dir / "a.log", 10);
  EXPECT_TRUE(ok.ok());
  EXPECT_EQ(Read(dir / "a.log"), "out\nerr\n");
  const ProcessResult bad = RunProcess({"/bin/sh", "-c", "exit 3"}, dir / "b.log", 10);
  EXPECT_FALSE(bad.ok());
  EXPECT_EQ(bad.exit_code, 3);
  EXPECT_EQ(bad.Describe(), "exit 3");
  EXPECT_THROW(RunProcess({"/nonexistent/program"}, dir / "c.log", 10), Error);
}

TEST(RunProcess, KillsOnTimeoutAndCancel) {
  const fs::path dir = testing::MakeTempDir("bench_process_timeout");
  const ProcessResult t = RunProcess({"/bin/sleep", "30"}, dir / "t.log", 0.3);
  EXPECT_TRUE(t.timed_out);
  EXPECT_FALSE(t.ok());
  EXPECT_LT(t.wall_s, 10.0);
  std::atomic<bool> cancel{true};
  const ProcessResult c = RunProcess({"/bin/sleep", "30"}, dir / "c.log", 100, &cancel);
  EXPECT_FALSE(c.timed_out);
  EXPECT_EQ(c.signal, SIGTERM);
}

TEST(ShellQuote, QuotesOnlyWhenNeeded) {
  EXPECT_EQ(ShellQuote("a/b-c.txt"), "a/b-c.txt");
  EXPECT_EQ(ShellQuote("a b"), "'a b'");
  EXPECT_EQ(ShellQuote("it's"), "'it'\\''s'");
  EXPECT_EQ(ShellQuote(""), "''");
  EXPECT_EQ(ShellCommand({"x", "y z"}), "x 'y z'");
}

TEST(FileLock, SerialisesHolders) {
  const fs::path dir = testing::MakeTempDir("bench_lock");
  auto holder = std::make_unique<FileLock>(dir / "l.lock");
  std::atomic<bool> acquired{false};
  std::thread other([&] {
    FileLock second(dir / "l.lock");  // flock locks are per open file: blocks here
    acquired.store(true);
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_FALSE(acquired.load());
  holder.reset();
  other.join();
  EXPECT_TRUE(acquired.load());
}

}  // namespace
}  // namespace pkslam::bench
