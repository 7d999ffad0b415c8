#include "tests/support/test_data.h"

#include <cstdio>
#include <cstdlib>
#include <random>

#include <sys/wait.h>

#include <fmt/format.h>

namespace pkslam::testing {

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

std::filesystem::path MakeTempDir(const std::string& prefix) {
  namespace fs = std::filesystem;
  std::random_device rd;
  for (int attempt = 0; attempt < 100; ++attempt) {
    const fs::path dir = fs::temp_directory_path() / fmt::format("pkslam_{}_{:08x}", prefix, rd());
    if (fs::create_directories(dir)) return dir;
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

}  // namespace pkslam::testing
