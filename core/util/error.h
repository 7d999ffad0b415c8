// Error types and checks. Libraries never exit(): they throw one of these (or return
// std::optional for queries that may legitimately fail); apps/ turns them into a one-line
// message and a non-zero exit code.
#pragma once

#include <fmt/format.h>

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace pkslam {

// A programming or numerical error inside pkslam (violated precondition).
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Bad user input: a file that is missing, empty, malformed, or inconsistent. The message
// names the file and, where there is one, the 1-based line.
class InputError : public Error {
 public:
  InputError(const std::filesystem::path& file, std::size_t line, const std::string& what)
      : Error(line > 0 ? fmt::format("{}:{}: {}", file.string(), line, what)
                       : fmt::format("{}: {}", file.string(), what)),
        file_(file),
        line_(line) {}
  InputError(const std::filesystem::path& file, const std::string& what)
      : InputError(file, 0, what) {}

  const std::filesystem::path& file() const { return file_; }
  std::size_t line() const { return line_; }

 private:
  std::filesystem::path file_;
  std::size_t line_ = 0;
};

// An output file that could not be written (disk full, no permission, a directory in the
// way). The message names the file and the system's reason.
class OutputError : public Error {
 public:
  OutputError(const std::filesystem::path& file, const std::string& what)
      : Error(fmt::format("cannot write {}: {}", file.string(), what)), file_(file) {}

  const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
};

// Bad option value (command line or options struct). Message names the option.
class OptionError : public Error {
 public:
  using Error::Error;
};

}  // namespace pkslam

// PKSLAM_CHECK(cond, "fmt {}", args...) throws pkslam::Error with file:line context.
#define PKSLAM_CHECK(cond, ...)                                                               \
  do {                                                                                        \
    if (!(cond)) {                                                                            \
      throw ::pkslam::Error(::fmt::format("{}:{}: check '{}' failed: {}", __FILE__, __LINE__, \
                                          #cond, ::fmt::format(__VA_ARGS__)));                \
    }                                                                                         \
  } while (false)

// PKSLAM_CHECK_OPTION(cond, "name", "reason") for options structs' Check().
#define PKSLAM_CHECK_OPTION(cond, name, ...)                                                      \
  do {                                                                                            \
    if (!(cond)) {                                                                                \
      throw ::pkslam::OptionError(                                                                \
          ::fmt::format("option {}: {} (requires {})", name, ::fmt::format(__VA_ARGS__), #cond)); \
    }                                                                                             \
  } while (false)
