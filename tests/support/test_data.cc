#include "tests/support/test_data.h"

#include <fmt/format.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <mutex>
#include <random>
#include <regex>
#include <vector>

namespace pkslam::testing {

std::string ReadFileBytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::optional<std::filesystem::path> SharedDataDir() {
  namespace fs = std::filesystem;
  if (const char* env = std::getenv("PKSLAM_SHARED_DATA"); env != nullptr && *env != '\0') {
    if (fs::is_directory(env)) return fs::path(env);
    return std::nullopt;
  }
  const fs::path beside = fs::path(PKSLAM_SOURCE_DIR).parent_path() / "shared" / "data";
  if (fs::is_directory(beside / "euroc") || fs::is_directory(beside / "evo")) return beside;
  return std::nullopt;
}

namespace {

// The directories MakeTempDir made in this test process, removed when it exits (end-to-end
// tests leave simulated sequences of ~150 MB; repeated ctest runs filled the disk) unless
// PKSLAM_KEEP_TEST_DIRS is set, for debugging a failure.
class TempDirRegistry {
 public:
  ~TempDirRegistry() {
    if (const char* keep = std::getenv("PKSLAM_KEEP_TEST_DIRS"); keep != nullptr && *keep != '\0') {
      return;
    }
    std::lock_guard lock(mutex_);
    for (const auto& dir : dirs_) {
      std::error_code ignored;
      std::filesystem::remove_all(dir, ignored);
    }
  }
  void Add(const std::filesystem::path& dir) {
    std::lock_guard lock(mutex_);
    dirs_.push_back(dir);
  }

 private:
  std::mutex mutex_;
  std::vector<std::filesystem::path> dirs_;
};

TempDirRegistry temp_dirs;

}  // namespace

std::filesystem::path MakeTempDir(const std::string& prefix) {
  namespace fs = std::filesystem;
  std::random_device rd;
  for (int attempt = 0; attempt < 100; ++attempt) {
    const fs::path dir = fs::temp_directory_path() / fmt::format("pkslam_{}_{:08x}", prefix, rd());
    if (fs::create_directories(dir)) {
      temp_dirs.Add(dir);
      return dir;
    }
  }
  throw std::runtime_error("cannot create a temporary directory");
}

std::filesystem::path PkslamExecutable() {
  if (const char* env = std::getenv("PKSLAM_EXECUTABLE"); env != nullptr && *env != '\0') {
    return env;
  }
  return std::filesystem::path(PKSLAM_BINARY_DIR) / "bin" / "pkslam";
}

CommandResult RunCommand(const std::string& command) {
  CommandResult result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[4096];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) result.output.append(buffer, n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

CommandResult RunPkslam(const std::string& args) {
  return RunCommand(fmt::format("'{}' {}", PkslamExecutable().string(), args));
}

long long JsonIntField(const std::filesystem::path& file, const std::string& key) {
  const std::string text = ReadFileBytes(file);
  std::smatch m;
  if (!std::regex_search(text, m, std::regex("\"" + key + "\": (-?[0-9]+)"))) return -1;
  return std::stoll(m[1].str());
}

}  // namespace pkslam::testing
