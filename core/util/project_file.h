// Files the executable needs from the source tree at run time (plot scripts, the vocabulary):
// found next to the running executable's build tree first (build/bin/pkslam -> the source
// folder above it), else in the source tree this binary was built from.
#pragma once

#include <filesystem>

namespace pkslam {

// `relative` (e.g. "bench/plots.py") under the first ancestor folder of the executable
// that has it; otherwise PKSLAM_SOURCE_DIR / relative, which may not exist (callers check).
std::filesystem::path FindProjectFile(const std::filesystem::path& relative);

}  // namespace pkslam
