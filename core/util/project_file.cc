#include "core/util/project_file.h"

namespace pkslam {

namespace fs = std::filesystem;

fs::path FindProjectFile(const fs::path& relative) {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (fs::path dir = exe.parent_path(); !dir.empty() && dir != dir.root_path();
         dir = dir.parent_path()) {
      if (fs::exists(dir / relative)) return dir / relative;
    }
  }
  return fs::path(PKSLAM_SOURCE_DIR) / relative;
}

}  // namespace pkslam
