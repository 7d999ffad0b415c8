// Which source tree an executable was built from, for results that must say where they came
// from (bench results.csv, `pkslam --version`). Run outputs do not carry it: `--deterministic`
// outputs stay byte-identical across commits that change nothing.
#pragma once

#include <string>

namespace pkslam {

// The git commit of the build ("unknown" outside a git checkout), with "-dirty" appended when
// tracked files differed from it.
std::string BuildCommit();

// "pkslam 0.1.0 (commit <40 hex digits>[-dirty], Release)": the --version line.
std::string BuildDescription();

}  // namespace pkslam
