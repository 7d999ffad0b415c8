// Shared by the fuzz targets: a per-process scratch directory for the readers that take a path,
// input splitting, quiet logging, the check of an expected InputError and the failure report of
// the harness' own checks.
#pragma once

#include <spdlog/sinks/null_sink.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "core/util/error.h"
#include "core/util/log.h"

namespace pkslam::fuzz {

// A fresh directory under $TMPDIR (or /tmp), unique to this process (libFuzzer's -fork and
// -jobs run several processes), removed at normal exit.
inline const std::filesystem::path& ScratchDir() {
  // Never destroyed, so that the exit handler can still use it.
  static const std::filesystem::path* const dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern =
        std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/pkslam_fuzz.XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) {
      std::perror("pkslam fuzz: mkdtemp");
      std::abort();
    }
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(ScratchDir(), ec);
    });
    return new std::filesystem::path(pattern);
  }();
  return *dir;
}

// Writes `size` bytes to ScratchDir()/name (replacing it) and returns the path.
inline std::filesystem::path WriteScratchFile(const std::string& name, const void* data,
                                              std::size_t size) {
  const std::filesystem::path file = ScratchDir() / name;
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "pkslam fuzz: cannot write %s\n", file.c_str());
    std::abort();
  }
  return file;
}

inline std::filesystem::path WriteScratchFile(const std::string& name, std::string_view text) {
  return WriteScratchFile(name, text.data(), text.size());
}

// `input` cut at every `separator` into at most `max_parts` parts (the last keeps the rest).
inline std::vector<std::string_view> SplitInput(std::string_view input, std::string_view separator,
                                                std::size_t max_parts) {
  std::vector<std::string_view> parts;
  while (parts.size() + 1 < max_parts) {
    const std::size_t at = input.find(separator);
    if (at == std::string_view::npos) break;
    parts.push_back(input.substr(0, at));
    input.remove_prefix(at + separator.size());
  }
  parts.push_back(input);
  return parts;
}

// Log messages are formatted (that code runs too) but go nowhere.
inline void QuietLogging() {
  auto logger = Logger();
  logger->sinks().clear();
  logger->sinks().push_back(std::make_shared<spdlog::sinks::null_sink_mt>());
  logger->set_level(spdlog::level::trace);
  logger->flush_on(spdlog::level::off);
}

// A broken invariant of the harness (e.g. a written file that does not read back): report and
// abort, which libFuzzer records as a crash.
[[noreturn]] inline void Finding(const std::string& what) {
  std::fprintf(stderr, "pkslam fuzz finding: %s\n", what.c_str());
  std::abort();
}

// The expected end of a bad input. It must name the file; PKSLAM_FUZZ_VERBOSE=1 prints it.
inline void Rejected(const InputError& e) {
  static const bool verbose = std::getenv("PKSLAM_FUZZ_VERBOSE") != nullptr;
  if (verbose) std::fprintf(stderr, "rejected: %s\n", e.what());
  if (e.file().empty()) Finding(std::string("InputError without a file: ") + e.what());
}

}  // namespace pkslam::fuzz
