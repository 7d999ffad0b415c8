// Scene files (YAML): a room, named materials (texture recipe + physical tile size), objects
// placed relative to the room, optional random scatter, lights. Positions are given relative
// to the room: x, y from the room centre, z above the floor; when the room is stretched to
// fit a trajectory, x and y scale with it. Built-in scenes live in sim/scenes/*.yaml and are
// compiled into the library. See sim/scenes/vicon_room.yaml for an annotated example.
#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "sim/texture_factory.h"

namespace pkslam::sim {

struct MaterialDesc {
  std::string name;
  TextureSpec texture;
  double tile_m = 1.0;   // metres per texture repeat
  bool stretch = false;  // texture once over the face (markers, posters)
  double albedo = 0.7;
  double macro_strength = 0.2;  // large-scale albedo variation (0: none)
  // Light the surface emits (windows, lamps), independent of the lights; in radiance units
  // where a white wall under the ambient light is ~0.5, so a few units saturate the camera.
  double emission = 0.0;
};

enum class ObjectType { kBox, kCylinder, kQuad, kShelf };

struct ObjectDesc {
  ObjectType type = ObjectType::kBox;
  std::string name;
  // Box/shelf: bottom centre (z = height of the base above the floor); cylinder: bottom
  // centre; quad: centre. x, y relative to the room centre.
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  // Box/shelf: full extents; cylinder: (diameter, diameter, height); quad: (width, height, 0).
  Eigen::Vector3d size = Eigen::Vector3d::Ones();
  double yaw_deg = 0.0;                // rotation about z
  std::vector<std::string> materials;  // one, or per face (box: 6); shelf: frame, goods...
  std::string wall;                    // quad only: "-x", "+x", "-y", "+y" attaches it
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // quad not on a wall: facing direction
  int levels = 4;                                     // shelf boards
  int line = 0;                                       // line in the YAML (messages)
};

enum class ScatterRegion { kAnywhere, kWalls, kPath };

struct ScatterDesc {
  ObjectType type = ObjectType::kBox;
  int count = 0;
  Eigen::Vector3d size_min = Eigen::Vector3d::Constant(0.3);
  Eigen::Vector3d size_max = Eigen::Vector3d::Constant(1.0);
  std::vector<std::string> materials;  // one chosen at random per object
  // Where the objects go: anywhere in the room, against the walls (within about 2 m), or along
  // the camera path (a horizontal distance in path_distance_m from a random path point; objects
  // within the builder's clearance of the path are still refused; without a path, anywhere),
  // which is how a scene puts structure at the distances a flight sees it from however large
  // the room grows. YAML: `region: anywhere|walls|path`, `distance: [min, max]` (path).
  ScatterRegion region = ScatterRegion::kAnywhere;
  Eigen::Vector2d path_distance_m = Eigen::Vector2d(2.0, 6.0);
  int levels = 4;                      // shelves
};

struct LightDesc {
  Eigen::Vector3d position = Eigen::Vector3d(0, 0, 3);  // relative like objects
  double intensity = 0.4;
  double range_m = 5.0;
};

struct SceneDescription {
  std::string name;
  std::filesystem::path source;  // file or "builtin:<name>"
  Eigen::Vector3d room_size = Eigen::Vector3d(8, 8, 4);
  Eigen::Vector2d room_center = Eigen::Vector2d::Zero();
  double floor_z = 0.0;
  // Room faces: -x, +x, -y, +y walls, floor, ceiling.
  std::array<std::string, 6> room_materials;
  double ambient = 0.6;
  std::vector<LightDesc> lights;
  std::vector<MaterialDesc> materials;
  std::vector<ObjectDesc> objects;
  std::vector<ScatterDesc> scatter;
  std::string texture_mode = "rich";  // rich|weak|repetitive (scene default; CLI may override)

  int MaterialIndex(const std::string& name) const;  // -1 when unknown
};

// Parses YAML text; errors are InputError naming `source` and the line. `extends: NAME`
// starts from another scene (built-in or file) and overrides name, ambient, texture_mode and
// adds materials, objects, scatter and lights.
SceneDescription ParseSceneYaml(const std::string& text, const std::filesystem::path& source);

// A built-in name (vicon_room, machine_hall, weak_texture, repetitive, marker_test) or a
// path to a YAML file.
SceneDescription LoadSceneDescription(const std::string& name_or_file);
std::vector<std::string> BuiltinSceneNames();

}  // namespace pkslam::sim
