#include "core/util/build_info.h"

#include "pkslam_build_info.h"  // generated: build/generated/

namespace pkslam {

std::string BuildCommit() {
  std::string commit = kPkslamGitCommit;
  if (kPkslamGitDirty) commit += "-dirty";
  return commit;
}

std::string BuildDescription() {
  return std::string("pkslam ") + PKSLAM_VERSION + " (commit " + BuildCommit() + ", " +
         PKSLAM_BUILD_TYPE + ")";
}

}  // namespace pkslam
