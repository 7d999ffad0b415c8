#include "core/util/output_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

#include "core/util/error.h"

namespace pkslam {
namespace {

std::string ErrnoMessage(int error) { return std::generic_category().message(error); }

// Writes all of `data` to `fd`, retrying short writes and EINTR. Returns 0 or an errno value.
int WriteAll(int fd, std::string_view data) {
  while (!data.empty()) {
    const ssize_t n = ::write(fd, data.data(), data.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    data.remove_prefix(static_cast<std::size_t>(n));
  }
  return 0;
}

}  // namespace

void WriteFileAtomically(const std::filesystem::path& file, std::string_view content) {
  // Same directory, so that the rename is atomic; the pid keeps concurrent writers apart.
  std::filesystem::path tmp = file;
  tmp += fmt::format(".tmp{}", ::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw OutputError(file, ErrnoMessage(errno));
  int error = WriteAll(fd, content);
  // close() reports delayed write errors on some file systems (NFS): check it too.
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error == 0 && ::rename(tmp.c_str(), file.c_str()) != 0) error = errno;
  if (error != 0) {
    ::unlink(tmp.c_str());
    throw OutputError(file, ErrnoMessage(error));
  }
}

AppendFile::AppendFile(std::filesystem::path file) : file_(std::move(file)) {
  fd_ = ::open(file_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) error_ = ErrnoMessage(errno);
}

AppendFile::~AppendFile() {
  if (fd_ >= 0) ::close(fd_);
}

void AppendFile::Append(std::string_view lines) {
  if (fd_ < 0 || !error_.empty()) return;
  if (const int error = WriteAll(fd_, lines); error != 0) error_ = ErrnoMessage(error);
}

}  // namespace pkslam
