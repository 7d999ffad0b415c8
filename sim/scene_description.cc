#include "sim/scene_description.h"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <map>
#include <sstream>

#include "core/util/error.h"
#include "sim/builtin_scenes.h"

namespace pkslam::sim {
namespace {

class Parser {
 public:
  explicit Parser(std::filesystem::path source) : source_(std::move(source)) {}

  [[noreturn]] void Fail(const YAML::Node& node, const std::string& what) const {
    throw InputError(source_, static_cast<std::size_t>(node.Mark().line + 1), what);
  }

  template <typename T>
  T Get(const YAML::Node& node, const std::string& key, T fallback) const {
    const YAML::Node v = node[key];
    if (!v) return fallback;
    try {
      return v.as<T>();
    } catch (const YAML::Exception&) {
      Fail(v, "bad value for '" + key + "'");
    }
  }

  Eigen::VectorXd Vec(const YAML::Node& node, const std::string& key, int n,
                      Eigen::VectorXd fallback) const {
    const YAML::Node v = node[key];
    if (!v) return fallback;
    if (!v.IsSequence() || static_cast<int>(v.size()) != n) {
      Fail(v, "'" + key + "' must be a list of " + std::to_string(n) + " numbers");
    }
    Eigen::VectorXd out(n);
    for (int i = 0; i < n; ++i) {
      try {
        out[i] = v[i].as<double>();
      } catch (const YAML::Exception&) {
        Fail(v, "'" + key + "' must be numbers");
      }
    }
    return out;
  }

  std::vector<std::string> Names(const YAML::Node& node, const std::string& key) const {
    const YAML::Node v = node[key];
    std::vector<std::string> out;
    if (!v) return out;
    if (v.IsScalar()) return {v.as<std::string>()};
    if (!v.IsSequence()) Fail(v, "'" + key + "' must be a name or a list of names");
    for (const auto& e : v) out.push_back(e.as<std::string>());
    return out;
  }

  TextureSpec Texture(const YAML::Node& node) const {
    TextureSpec t;
    const std::string kind = Get<std::string>(node, "kind", "noise");
    if (kind == "photo") {
      t.kind = TextureKind::kPhoto;
    } else if (kind == "noise") {
      t.kind = TextureKind::kNoise;
    } else if (kind == "weak") {
      t.kind = TextureKind::kWeak;
    } else if (kind == "repetitive") {
      t.kind = TextureKind::kRepetitive;
    } else if (kind == "checker") {
      t.kind = TextureKind::kChecker;
    } else if (kind == "quilted") {
      t.kind = TextureKind::kQuilted;
    } else if (kind == "confetti") {
      t.kind = TextureKind::kConfetti;
    } else {
      Fail(node, "unknown texture kind '" + kind +
                     "' (photo|noise|weak|repetitive|checker|quilted|confetti)");
    }
    t.photo = Get<std::string>(node, "photo", "");
    if ((t.kind == TextureKind::kPhoto) && t.photo.empty())
      Fail(node, "photo texture needs 'photo'");
    t.size = Get<int>(node, "size", 0);  // 0: the build's quality default
    t.contrast = Get<double>(node, "contrast", t.contrast);
    t.detail = Get<double>(node, "detail", t.detail);
    t.base_cells = Get<int>(node, "base_cells", t.base_cells);
    t.max_cells = Get<int>(node, "max_cells", t.max_cells);
    t.speckle = Get<double>(node, "speckle", t.speckle);
    t.tint = Vec(node, "tint", 3, Eigen::Vector3d::Ones());
    t.checker_cols = Get<int>(node, "cols", t.checker_cols);
    t.checker_rows = Get<int>(node, "rows", t.checker_rows);
    t.checker_square_px = Get<int>(node, "square_px", t.checker_square_px);
    t.stripes = Get<int>(node, "stripes", t.stripes);
    t.seam_depth = Get<double>(node, "seam_depth", t.seam_depth);
    t.flakes = Get<int>(node, "flakes", t.flakes);
    t.flake_size = Get<double>(node, "flake_size", t.flake_size);
    return t;
  }

  ObjectType Type(const YAML::Node& node) const {
    const std::string type = Get<std::string>(node, "type", "");
    if (type == "box") return ObjectType::kBox;
    if (type == "cylinder") return ObjectType::kCylinder;
    if (type == "quad") return ObjectType::kQuad;
    if (type == "shelf") return ObjectType::kShelf;
    Fail(node, "unknown object type '" + type + "' (box|cylinder|quad|shelf)");
  }

  ObjectDesc Object(const YAML::Node& node) const {
    ObjectDesc o;
    o.type = Type(node);
    o.line = node.Mark().line + 1;
    o.name = Get<std::string>(node, "name", "");
    o.position = Vec(node, "position", 3, Eigen::Vector3d::Zero());
    if (o.type == ObjectType::kCylinder) {
      const double r = Get<double>(node, "radius", 0.25);
      o.size = Eigen::Vector3d(2 * r, 2 * r, Get<double>(node, "height", 2.0));
    } else if (o.type == ObjectType::kQuad) {
      const Eigen::Vector2d s = Vec(node, "size", 2, Eigen::Vector2d(1, 1));
      o.size = Eigen::Vector3d(s.x(), s.y(), 0.0);
    } else {
      o.size = Vec(node, "size", 3, Eigen::Vector3d::Ones());
    }
    if ((o.size.array() < 0.0).any() || o.size.x() <= 0 || o.size.y() <= 0) {
      Fail(node, "object size must be positive");
    }
    o.yaw_deg = Get<double>(node, "yaw_deg", 0.0);
    o.materials = Names(node, "material");
    if (o.materials.empty()) o.materials = Names(node, "materials");
    if (o.materials.empty()) Fail(node, "object needs 'material'");
    o.wall = Get<std::string>(node, "wall", "");
    if (!o.wall.empty() && o.wall != "-x" && o.wall != "+x" && o.wall != "-y" && o.wall != "+y") {
      Fail(node, "wall must be one of -x, +x, -y, +y");
    }
    o.normal = Vec(node, "normal", 3, Eigen::Vector3d::UnitZ());
    if (o.normal.norm() < 1e-9) Fail(node, "quad normal must be non-zero");
    o.normal.normalize();
    o.levels = Get<int>(node, "levels", 4);
    if (o.levels < 1 || o.levels > 12) Fail(node, "shelf levels must be in [1, 12]");
    return o;
  }

 private:
  std::filesystem::path source_;
};

}  // namespace

namespace {
void ParseRoom(const Parser& p, const YAML::Node& room, SceneDescription* d);
void ParseContents(const Parser& p, const YAML::Node& root, SceneDescription* d);
}  // namespace

int SceneDescription::MaterialIndex(const std::string& name) const {
  for (int i = 0; i < static_cast<int>(materials.size()); ++i) {
    if (materials[i].name == name) return i;
  }
  return -1;
}

SceneDescription ParseSceneYaml(const std::string& text, const std::filesystem::path& source) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw InputError(source, static_cast<std::size_t>(e.mark.line + 1), e.msg);
  }
  if (!root.IsMap()) throw InputError(source, "scene file must be a YAML map");
  const Parser p(source);
  SceneDescription d;
  const bool extends = static_cast<bool>(root["extends"]);
  if (extends) {
    const std::string base = p.Get<std::string>(root, "extends", "");
    if (base == source.stem().string()) p.Fail(root["extends"], "a scene cannot extend itself");
    d = LoadSceneDescription(base);
  }
  d.source = source;
  d.name = p.Get<std::string>(root, "name", source.stem().string());
  d.ambient = p.Get<double>(root, "ambient", d.ambient);
  d.texture_mode = p.Get<std::string>(root, "texture_mode", d.texture_mode);
  if (d.texture_mode != "rich" && d.texture_mode != "weak" && d.texture_mode != "repetitive") {
    p.Fail(root["texture_mode"], "texture_mode must be rich, weak or repetitive");
  }

  const YAML::Node mats = root["materials"];
  if (!extends && (!mats || !mats.IsMap())) {
    throw InputError(source, "scene needs a 'materials' map");
  }
  for (const auto& kv : mats) {
    MaterialDesc m;
    m.name = kv.first.as<std::string>();
    const YAML::Node& n = kv.second;
    if (!n["texture"]) p.Fail(n, "material '" + m.name + "' needs 'texture'");
    m.texture = p.Texture(n["texture"]);
    m.tile_m = p.Get<double>(n, "tile", m.tile_m);
    m.stretch = p.Get<bool>(n, "stretch", m.stretch);
    m.albedo = p.Get<double>(n, "albedo", m.albedo);
    m.macro_strength = p.Get<double>(n, "macro", m.macro_strength);
    m.emission = p.Get<double>(n, "emission", m.emission);
    if (!(m.tile_m > 0) || !(m.albedo > 0) || m.macro_strength < 0 || m.macro_strength > 0.5 ||
        !(m.emission >= 0 && m.emission <= 1000)) {
      p.Fail(n, "material '" + m.name +
                    "': tile > 0, albedo > 0, macro in [0, 0.5], emission in [0, 1000]");
    }
    const int existing = d.MaterialIndex(m.name);
    if (existing >= 0) {
      d.materials[existing] = m;
    } else {
      d.materials.push_back(m);
    }
  }
  const YAML::Node room = root["room"];
  if (!room && !extends) throw InputError(source, "scene needs a 'room'");
  if (room) ParseRoom(p, room, &d);
  ParseContents(p, root, &d);
  return d;
}

namespace {

void ParseRoom(const Parser& p, const YAML::Node& room, SceneDescription* dp) {
  SceneDescription& d = *dp;
  auto check_material = [&](const YAML::Node& n, const std::string& name) {
    if (d.MaterialIndex(name) < 0) p.Fail(n, "unknown material '" + name + "'");
  };
  d.room_size = p.Vec(room, "size", 3, d.room_size);
  if ((d.room_size.array() <= 0.5).any()) p.Fail(room, "room size must be > 0.5 m");
  d.room_center = p.Vec(room, "center", 2, d.room_center);
  d.floor_z = p.Get<double>(room, "floor_z", d.floor_z);
  const YAML::Node rm = room["materials"];
  if (!rm) p.Fail(room, "room needs 'materials' (walls, floor, ceiling)");
  const std::vector<std::string> walls = p.Names(rm, "walls");
  if (walls.size() != 1 && walls.size() != 4) p.Fail(rm, "room walls: one or four materials");
  for (int i = 0; i < 4; ++i) d.room_materials[i] = walls[walls.size() == 1 ? 0 : i];
  d.room_materials[4] = p.Get<std::string>(rm, "floor", "");
  d.room_materials[5] = p.Get<std::string>(rm, "ceiling", "");
  for (const auto& m : d.room_materials) check_material(rm, m);
}

void ParseContents(const Parser& p, const YAML::Node& root, SceneDescription* dp) {
  SceneDescription& d = *dp;
  auto check_material = [&](const YAML::Node& n, const std::string& name) {
    if (d.MaterialIndex(name) < 0) p.Fail(n, "unknown material '" + name + "'");
  };
  for (const auto& n : root["lights"]) {
    LightDesc l;
    l.position = p.Vec(n, "position", 3, l.position);
    l.intensity = p.Get<double>(n, "intensity", l.intensity);
    l.range_m = p.Get<double>(n, "range", l.range_m);
    if (l.intensity < 0 || !(l.range_m > 0)) p.Fail(n, "light intensity >= 0 and range > 0");
    d.lights.push_back(l);
  }
  for (const auto& n : root["objects"]) {
    ObjectDesc o = p.Object(n);
    for (const auto& m : o.materials) check_material(n, m);
    d.objects.push_back(o);
  }
  for (const auto& n : root["scatter"]) {
    ScatterDesc s;
    s.type = p.Type(n);
    s.count = p.Get<int>(n, "count", 0);
    s.size_min = p.Vec(n, "size_min", 3, s.size_min);
    s.size_max = p.Vec(n, "size_max", 3, s.size_max);
    s.materials = p.Names(n, "materials");
    const auto region = p.Get<std::string>(n, "region", "anywhere");
    if (region == "walls") {
      s.region = ScatterRegion::kWalls;
    } else if (region == "path") {
      s.region = ScatterRegion::kPath;
      s.path_distance_m = p.Vec(n, "distance", 2, s.path_distance_m);
      if (!(s.path_distance_m.x() >= 0.0 && s.path_distance_m.y() > s.path_distance_m.x())) {
        p.Fail(n, "scatter distance: [min, max] metres with 0 <= min < max");
      }
    } else if (region != "anywhere") {
      p.Fail(n, "scatter region must be anywhere, walls or path, got '" + region + "'");
    }
    s.levels = p.Get<int>(n, "levels", s.levels);
    if (s.count < 0 || s.count > 2000 || s.materials.empty() || (s.size_min.array() <= 0).any() ||
        (s.size_max - s.size_min).minCoeff() < 0) {
      p.Fail(n, "scatter: count in [0, 2000], materials, 0 < size_min <= size_max");
    }
    for (const auto& m : s.materials) check_material(n, m);
    d.scatter.push_back(s);
  }
}

}  // namespace

std::vector<std::string> BuiltinSceneNames() {
  std::vector<std::string> names;
  for (const auto& s : BuiltinScenes()) names.emplace_back(s.name);
  return names;
}

SceneDescription LoadSceneDescription(const std::string& name_or_file) {
  for (const auto& s : BuiltinScenes()) {
    if (name_or_file == s.name) {
      return ParseSceneYaml(std::string(s.yaml), "builtin:" + std::string(s.name));
    }
  }
  const std::filesystem::path path(name_or_file);
  std::ifstream in(path);
  if (!in) {
    std::string known;
    for (const auto& n : BuiltinSceneNames()) known += (known.empty() ? "" : ", ") + n;
    throw InputError(path, "no such scene file (built-in scenes: " + known + ")");
  }
  std::stringstream text;
  text << in.rdbuf();
  return ParseSceneYaml(text.str(), path);
}

}  // namespace pkslam::sim
