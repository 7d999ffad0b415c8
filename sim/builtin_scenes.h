// The built-in scene YAML files (sim/scenes/*.yaml), compiled into the library by CMake so the
// binary does not depend on the source tree.
#pragma once

#include <span>
#include <string_view>

namespace pkslam::sim {

struct BuiltinScene {
  std::string_view name;  // file stem
  std::string_view yaml;
};

std::span<const BuiltinScene> BuiltinScenes();

}  // namespace pkslam::sim
