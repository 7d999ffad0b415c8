#include "io/json_file.h"

#include "core/util/error.h"

namespace pkslam {

YAML::Node ReadJsonFile(const std::filesystem::path& file) {
  try {
    return YAML::LoadFile(file.string());
  } catch (const YAML::Exception& e) {
    throw InputError(file, e.mark.line + 1, "not valid JSON: " + e.msg);
  }
}

}  // namespace pkslam
