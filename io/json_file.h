// Reading the JSON files pkslam writes (stats.json, dense --json): plain JSON is YAML flow
// style, so yaml-cpp parses it; a malformed file is an InputError naming the file and line.
#pragma once

#include <yaml-cpp/yaml.h>

#include <filesystem>

namespace pkslam {

// The parsed file (the caller checks existence first when a missing file means something).
YAML::Node ReadJsonFile(const std::filesystem::path& file);

}  // namespace pkslam
