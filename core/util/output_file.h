// Output files that are either complete or absent. A run that dies (full disk, SIGKILL, a
// second Ctrl-C) must not leave a trajectory cut in the middle that `pkslam eval` would read
// as a shorter run: every output is written under a temporary name beside its final one and
// renamed over it only once all bytes are on disk. Write errors (ENOSPC, EACCES, EFBIG) become
// OutputError naming the final file.
#pragma once

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <string_view>

namespace pkslam {

// Writes `content` to `file` atomically (temporary file + rename). Throws OutputError.
void WriteFileAtomically(const std::filesystem::path& file, std::string_view content);

// A text or binary output assembled in memory and published by Commit(). Outputs are at most
// tens of MB (map points, sparse models), so buffering keeps the write a single checked step.
// Not committed (an exception on the way): nothing is written.
class OutputFile {
 public:
  explicit OutputFile(std::filesystem::path file) : file_(std::move(file)) {}

  std::ostream& stream() { return buffer_; }
  const std::filesystem::path& path() const { return file_; }

  // Writes and renames; throws OutputError.
  void Commit() { WriteFileAtomically(file_, buffer_.view()); }

 private:
  std::filesystem::path file_;
  std::ostringstream buffer_;
};

// An append-only file whose every Append() is one write(2) of whole lines, so that a process
// killed at any moment leaves only whole lines (the trajectory-so-far of a run). The first
// failure is remembered (ok() turns false, error() says why) and later appends are dropped: a
// run does not stop because its crash-safety copy could not be written.
class AppendFile {
 public:
  // Creates or truncates `file`; on failure ok() is false.
  explicit AppendFile(std::filesystem::path file);
  ~AppendFile();
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;

  void Append(std::string_view lines);
  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  const std::filesystem::path& path() const { return file_; }

 private:
  std::filesystem::path file_;
  int fd_ = -1;
  std::string error_;
};

}  // namespace pkslam
