// Turns a SceneDescription into a renderable Scene: builds the textures, sizes the room so a
// given camera path fits inside with margins, places objects and random scatter, and removes
// every object (whole shelves included) that comes within the clearance radius of the path.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "sim/scene.h"
#include "sim/scene_description.h"

namespace pkslam::sim {

enum class TextureMode {
  kRich,       // as described
  kWeak,       // every tiled material becomes low-contrast smooth noise (markers kept)
  kRepetitive  // every tiled material becomes one motif repeated on a grid
};
TextureMode ParseTextureMode(const std::string& name);  // rich|weak|repetitive; OptionError
std::string TextureModeName(TextureMode mode);

struct SceneBuildOptions {
  int texture_size = 1024;  // base size of tiled textures (power of two)
  bool colour = false;      // also build colour textures (RGB-D output)
  TextureMode texture_mode = TextureMode::kRich;
  double clearance_m = 0.6;         // objects closer than this to the path are removed
  double wall_margin_m = 1.0;       // walls at least this far from the path (room grows)
  double floor_margin_m = 0.3;      // floor at least this far below the path
  double ceiling_margin_m = 0.5;    // ceiling at least this far above the path
  std::uint64_t seed = 0;           // scatter placement and texture noise
  std::filesystem::path photo_dir;  // empty: DefaultPhotoDir()

  void Check() const;
};

struct SceneBuildReport {
  Eigen::Vector3d room_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d room_max = Eigen::Vector3d::Zero();
  int objects_placed = 0;                   // objects (groups) before the clearance check
  int objects_removed = 0;                  // removed for clearance
  std::vector<std::string> missing_photos;  // textures that fell back to noise
};

// path: world positions the camera rig will occupy (may be empty: nominal room).
Scene BuildScene(const SceneDescription& description, const SceneBuildOptions& options,
                 const std::vector<Eigen::Vector3d>& path, SceneBuildReport* report = nullptr);

}  // namespace pkslam::sim
