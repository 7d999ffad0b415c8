#include "sim/scene_builder.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "core/util/error.h"
#include "core/util/log.h"
#include "sim/random.h"

namespace pkslam::sim {

TextureMode ParseTextureMode(const std::string& name) {
  if (name == "rich") return TextureMode::kRich;
  if (name == "weak") return TextureMode::kWeak;
  if (name == "repetitive") return TextureMode::kRepetitive;
  throw OptionError("texture mode must be rich, weak or repetitive, got '" + name + "'");
}

std::string TextureModeName(TextureMode mode) {
  switch (mode) {
    case TextureMode::kRich:
      return "rich";
    case TextureMode::kWeak:
      return "weak";
    case TextureMode::kRepetitive:
      return "repetitive";
  }
  return "?";
}

void SceneBuildOptions::Check() const {
  PKSLAM_CHECK_OPTION(
      texture_size >= 16 && texture_size <= 8192 && (texture_size & (texture_size - 1)) == 0,
      "scene.texture_size", "{}", texture_size);
  PKSLAM_CHECK_OPTION(clearance_m >= 0.0, "scene.clearance_m", "{}", clearance_m);
  PKSLAM_CHECK_OPTION(wall_margin_m >= 0.0 && floor_margin_m >= 0.0 && ceiling_margin_m >= 0.0,
                      "scene margins", "must be >= 0");
}

namespace {

// Places description-relative coordinates into the fitted room.
struct RoomFrame {
  Eigen::Vector3d min;
  Eigen::Vector3d max;
  Eigen::Vector2d scale;  // fitted / nominal size in x, y

  Eigen::Vector3d centre() const { return 0.5 * (min + max); }
  Eigen::Vector3d Place(const Eigen::Vector3d& rel) const {
    const Eigen::Vector3d c = centre();
    return {c.x() + rel.x() * scale.x(), c.y() + rel.y() * scale.y(), min.z() + rel.z()};
  }
};

Eigen::Matrix3f Yaw(double deg) {
  return Eigen::AngleAxisf(static_cast<float>(deg * std::numbers::pi / 180.0),
                           Eigen::Vector3f::UnitZ())
      .toRotationMatrix();
}

class Builder {
 public:
  Builder(const SceneDescription& d, const SceneBuildOptions& o)
      : d_(d), rng_(DeriveSeed(o.seed, 0x5343454E45)) {}

  int Material(const std::string& name) const { return d_.MaterialIndex(name); }

  Shape NewShape(ShapeType type, const std::string& name, int group) {
    Shape s;
    s.type = type;
    s.name = name;
    s.group = group;
    s.uv_offset.x() = static_cast<float>(rng_.Uniform(0.0, 10.0));
    s.uv_offset.y() = static_cast<float>(rng_.Uniform(0.0, 10.0));
    return s;
  }

  void SetMaterials(Shape* s, const std::vector<std::string>& names) {
    for (int f = 0; f < 6; ++f) {
      s->material[f] = Material(names.size() == 6 ? names[f] : names.front());
    }
  }

  // Box with its bottom centre at `base` (world), rotated by `rot`.
  void AddBox(const Eigen::Vector3f& base, const Eigen::Vector3f& size, const Eigen::Matrix3f& rot,
              const std::vector<std::string>& materials, const std::string& name, int group,
              std::vector<Shape>* out) {
    Shape s = NewShape(ShapeType::kBox, name, group);
    s.world_from_local = rot;
    s.half = 0.5f * size;
    s.center = base + rot * Eigen::Vector3f(0, 0, 0.5f * size.z());
    SetMaterials(&s, materials);
    out->push_back(s);
  }

  void AddShelf(const Eigen::Vector3f& base, const Eigen::Vector3f& size,
                const Eigen::Matrix3f& rot, const std::vector<std::string>& materials, int levels,
                const std::string& name, int group, std::vector<Shape>* out) {
    const std::vector<std::string> frame{materials.front()};
    const float w = size.x();
    const float dpt = size.y();
    const float h = size.z();
    auto part = [&](const Eigen::Vector3f& local_base, const Eigen::Vector3f& part_size,
                    const std::vector<std::string>& mats) {
      AddBox(base + rot * local_base, part_size, rot, mats, name, group, out);
    };
    const float side = 0.04f;
    part({-0.5f * w + 0.5f * side, 0, 0}, {side, dpt, h}, frame);
    part({0.5f * w - 0.5f * side, 0, 0}, {side, dpt, h}, frame);
    part({0, 0.5f * dpt - 0.01f, 0}, {w - 2 * side, 0.02f, h}, frame);
    const float board = 0.03f;
    const float spacing = (h - board) / static_cast<float>(levels);
    for (int i = 0; i <= levels; ++i) {
      const float z = std::min(0.08f + i * spacing, h - board);
      part({0, 0, z}, {w - 2 * side, dpt, board}, frame);
      if (i == levels || materials.size() < 2) continue;
      // Goods: boxes side by side along the board.
      float x = -0.5f * w + side + static_cast<float>(rng_.Uniform(0.0, 0.1));
      while (true) {
        const float gw = static_cast<float>(rng_.Uniform(0.12, 0.45));
        if (x + gw > 0.5f * w - side - 0.02f) break;
        const float gd = static_cast<float>(rng_.Uniform(0.5, 0.9)) * (dpt - 0.05f);
        const float gh = static_cast<float>(rng_.Uniform(0.35, 0.85)) * (spacing - board);
        const std::string& mat =
            materials[1 + rng_.UniformInt(static_cast<int>(materials.size()) - 1)];
        part({x + 0.5f * gw, -0.5f * dpt + 0.5f * gd + 0.02f, z + board}, {gw, gd, gh}, {mat});
        x += gw + static_cast<float>(rng_.Uniform(0.02, 0.2));
      }
    }
  }

  void AddObject(const ObjectDesc& o, const RoomFrame& room, int group, std::vector<Shape>* out) {
    const std::string name = o.name.empty() ? fmt::format("object@{}", o.line) : o.name;
    const Eigen::Matrix3f rot = Yaw(o.yaw_deg);
    switch (o.type) {
      case ObjectType::kBox:
        AddBox(room.Place(o.position).cast<float>(), o.size.cast<float>(), rot, o.materials, name,
               group, out);
        return;
      case ObjectType::kShelf:
        AddShelf(room.Place(o.position).cast<float>(), o.size.cast<float>(), rot, o.materials,
                 o.levels, name, group, out);
        return;
      case ObjectType::kCylinder: {
        Shape s = NewShape(ShapeType::kCylinder, name, group);
        s.half = Eigen::Vector3f(0.5f * o.size.x(), 0.5f * o.size.x(), 0.5f * o.size.z());
        s.center = room.Place(o.position).cast<float>() + Eigen::Vector3f(0, 0, s.half.z());
        SetMaterials(&s, o.materials);
        out->push_back(s);
        return;
      }
      case ObjectType::kQuad: {
        Shape s = NewShape(ShapeType::kQuad, name, group);
        s.half = Eigen::Vector3f(0.5f * o.size.x(), 0.5f * o.size.y(), 0.0f);
        Eigen::Vector3f normal;
        Eigen::Vector3f centre;
        if (!o.wall.empty()) {
          // On a wall: position.x runs along the wall, position.z is the height of the centre.
          const int axis = o.wall[1] == 'x' ? 0 : 1;
          const bool plus = o.wall[0] == '+';
          const Eigen::Vector3d c = room.centre();
          centre = Eigen::Vector3f::Zero();
          const int along = 1 - axis;
          centre[along] = static_cast<float>(c[along] + o.position.x() * room.scale[along]);
          centre[axis] = static_cast<float>(plus ? room.max[axis] - 0.005 : room.min[axis] + 0.005);
          centre.z() = static_cast<float>(room.min.z() + o.position.z());
          normal = Eigen::Vector3f::Zero();
          normal[axis] = plus ? -1.0f : 1.0f;
        } else {
          centre = room.Place(o.position).cast<float>();
          normal = o.normal.cast<float>();
        }
        Eigen::Vector3f up =
            std::abs(normal.z()) > 0.9f ? Eigen::Vector3f::UnitY() : Eigen::Vector3f::UnitZ();
        Eigen::Vector3f x_axis = up.cross(normal).normalized();
        up = normal.cross(x_axis);
        if (o.yaw_deg != 0.0) {  // turned about its normal (floor decals, tilted posters)
          const float a = static_cast<float>(o.yaw_deg * M_PI / 180.0);
          const Eigen::Vector3f x = std::cos(a) * x_axis + std::sin(a) * up;
          up = normal.cross(x);
          x_axis = x;
        }
        s.world_from_local.col(0) = x_axis;
        s.world_from_local.col(1) = up;
        s.world_from_local.col(2) = normal;
        s.center = centre;
        SetMaterials(&s, o.materials);
        out->push_back(s);
        return;
      }
    }
  }

  Rng& rng() { return rng_; }

 private:
  const SceneDescription& d_;
  Rng rng_;
};

// Where one scattered object of `size` goes (floor position, yaw) in its region; nullopt when the
// draw falls outside the room (the caller draws again). The draw order is part of every scene's
// identity: the path region's draws come only for that region, so other scenes keep theirs.
struct ScatterPlacement {
  Eigen::Vector3d position;
  double yaw_deg = 0.0;
};

std::optional<ScatterPlacement> DrawPlacement(const ScatterDesc& s, const RoomFrame& room,
                                              const std::vector<Eigen::Vector3d>& path,
                                              const Eigen::Vector3d& size, Rng* rng) {
  const Eigen::Vector3d extent = room.max - room.min;
  const double half_xy = 0.5 * std::hypot(size.x(), size.y());
  ScatterPlacement p;
  p.position = Eigen::Vector3d(0, 0, room.min.z());
  Eigen::Vector3d& pos = p.position;
  p.yaw_deg = rng->Uniform(0.0, 360.0);
  if (s.region == ScatterRegion::kPath && !path.empty()) {
    const Eigen::Vector3d& anchor = path[rng->UniformInt(static_cast<int>(path.size()))];
    const double angle = rng->Uniform(0.0, 2.0 * std::numbers::pi);
    const double distance = rng->Uniform(s.path_distance_m.x(), s.path_distance_m.y()) +
                            0.5 * std::min(size.x(), size.y());
    pos.x() = anchor.x() + distance * std::cos(angle);
    pos.y() = anchor.y() + distance * std::sin(angle);
    const Eigen::Vector2d lo = room.min.head<2>().array() + half_xy + 0.1;
    const Eigen::Vector2d hi = room.max.head<2>().array() - half_xy - 0.1;
    if ((pos.head<2>().array() < lo.array()).any() || (pos.head<2>().array() > hi.array()).any()) {
      return std::nullopt;
    }
  } else if (s.region == ScatterRegion::kWalls) {
    const int wall = rng->UniformInt(4);
    const int axis = wall / 2;
    const int along = 1 - axis;
    const double depth = rng->Uniform(0.05, 1.5) + 0.5 * size.y();
    pos[axis] = wall % 2 == 0 ? room.min[axis] + depth : room.max[axis] - depth;
    pos[along] = rng->Uniform(room.min[along] + half_xy, room.max[along] - half_xy);
    p.yaw_deg = (axis == 0 ? 90.0 : 0.0) + rng->Uniform(-8.0, 8.0);
  } else {
    pos.x() = room.min.x() + rng->Uniform(half_xy + 0.1, extent.x() - half_xy - 0.1);
    pos.y() = room.min.y() + rng->Uniform(half_xy + 0.1, extent.y() - half_xy - 0.1);
  }
  return p;
}

bool TooClose(const std::vector<Shape>& shapes, const std::vector<Eigen::Vector3d>& path,
              double clearance) {
  for (const Shape& s : shapes) {
    // Flat decals (quads: tape on the floor, posters) cannot be flown into; removing them
    // would only empty the floor under a take-off.
    if (s.type == ShapeType::kQuad) continue;
    const float reach = s.bound_radius() + static_cast<float>(clearance);
    for (const auto& p : path) {
      const Eigen::Vector3f pf = p.cast<float>();
      if ((pf - s.center).squaredNorm() > reach * reach) continue;
      if (SignedDistance(s, pf) < clearance) return true;
    }
  }
  return false;
}

// Footprint overlap of two objects' bounding circles in the floor plane.
bool Overlaps(const std::vector<Shape>& a, const std::vector<Shape>& b, float gap) {
  for (const Shape& s : a) {
    for (const Shape& t : b) {
      const float rs = std::hypot(s.half.x(), s.half.y());
      const float rt = std::hypot(t.half.x(), t.half.y());
      if ((s.center.head<2>() - t.center.head<2>()).norm() < rs + rt + gap) return true;
    }
  }
  return false;
}

// The described room, grown to hold the path with margins.
RoomFrame FitRoom(const SceneDescription& d, const SceneBuildOptions& options,
                  const std::vector<Eigen::Vector3d>& path) {
  RoomFrame room;
  room.min = Eigen::Vector3d(d.room_center.x() - 0.5 * d.room_size.x(),
                             d.room_center.y() - 0.5 * d.room_size.y(), d.floor_z);
  room.max = room.min + d.room_size;
  if (!path.empty()) {
    Eigen::Vector3d lo = path.front();
    Eigen::Vector3d hi = path.front();
    for (const auto& p : path) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const Eigen::Vector3d low_margin(options.wall_margin_m, options.wall_margin_m,
                                     options.floor_margin_m);
    const Eigen::Vector3d high_margin(options.wall_margin_m, options.wall_margin_m,
                                      options.ceiling_margin_m);
    room.min = room.min.cwiseMin(lo - low_margin);
    room.max = room.max.cwiseMax(hi + high_margin);
  }
  room.scale = (room.max - room.min).head<2>().cwiseQuotient(d.room_size.head<2>());
  return room;
}

// One texture and material per described material, then the shared macro-variation texture.
void AddMaterials(const SceneDescription& d, const SceneBuildOptions& options,
                  const std::filesystem::path& photo_dir, Scene* scene, SceneBuildReport* rep) {
  for (std::size_t i = 0; i < d.materials.size(); ++i) {
    const MaterialDesc& m = d.materials[i];
    TextureSpec spec = m.texture;
    if (spec.size == 0) spec.size = options.texture_size;
    // Small (fast/test) textures cannot hold the finest octaves a scene asks for.
    spec.base_cells = std::min(spec.base_cells, spec.size);
    if (spec.max_cells > 0) spec.max_cells = std::min(spec.max_cells, spec.size);
    spec.seed = DeriveSeed(options.seed, 0x54455800 + i);
    const bool tiled = !m.stretch && spec.kind != TextureKind::kChecker;
    if (tiled && options.texture_mode == TextureMode::kWeak) {
      spec.kind = TextureKind::kWeak;
      spec.contrast = 0.035;
      spec.base_cells = 2;
    } else if (tiled && options.texture_mode == TextureMode::kRepetitive) {
      spec.kind = TextureKind::kRepetitive;
    }
    bool fallback = false;
    scene->textures.push_back(BuildTexture(spec, photo_dir, options.colour, &fallback));
    if (fallback) rep->missing_photos.push_back(spec.photo);
    Material mat;
    mat.texture = static_cast<int>(i);
    mat.tile_m = static_cast<float>(m.tile_m);
    mat.stretch = m.stretch;
    mat.albedo = static_cast<float>(m.albedo);
    mat.macro_strength = static_cast<float>(m.macro_strength);
    mat.emission = static_cast<float>(m.emission);
    // Procedural noise is seamless and has no recognisable motif: shuffling would only add seams.
    mat.shuffle_tiles = spec.kind == TextureKind::kPhoto;
    scene->materials.push_back(mat);
  }
  TextureSpec macro;
  macro.kind = TextureKind::kNoise;
  macro.size = 256;
  macro.base_cells = 2;
  macro.max_cells = 32;
  macro.contrast = 0.25;
  macro.seed = DeriveSeed(options.seed, 0x4D4143);
  scene->textures.push_back(BuildTexture(macro, photo_dir, false));
  for (Material& m : scene->materials) {
    if (m.macro_strength > 0.0f) {
      m.macro_texture = static_cast<int>(scene->textures.size()) - 1;
      m.macro_tile_m = 9.0f;
    }
  }
}

// Scatter: random placements that avoid the path and each other from the start, appended to
// `groups` (object groups so far) with ids from `group_id` on. Their own random stream (not the
// builder's, which every shape draws texture offsets from), so adding an object to a scene does
// not move every scattered one.
void ScatterObjects(const SceneDescription& d, const SceneBuildOptions& options,
                    const RoomFrame& room, const std::vector<Eigen::Vector3d>& path,
                    Builder* builder, int* group_id, std::vector<std::vector<Shape>>* groups) {
  Rng rng(DeriveSeed(options.seed, 0x5343415454));
  for (const ScatterDesc& s : d.scatter) {
    for (int i = 0; i < s.count; ++i) {
      for (int attempt = 0; attempt < 60; ++attempt) {
        Eigen::Vector3d size;
        for (int k = 0; k < 3; ++k) size[k] = rng.Uniform(s.size_min[k], s.size_max[k]);
        const std::optional<ScatterPlacement> placed = DrawPlacement(s, room, path, size, &rng);
        if (!placed) continue;
        ObjectDesc o;
        o.type = s.type;
        o.size = size;
        o.yaw_deg = placed->yaw_deg;
        o.levels = s.levels;
        o.name = fmt::format("scatter{}", *group_id);
        if (s.type == ObjectType::kShelf) {
          o.materials = s.materials;
        } else {
          o.materials = {s.materials[rng.UniformInt(static_cast<int>(s.materials.size()))]};
        }
        if (s.type == ObjectType::kCylinder) o.size.y() = o.size.x();
        // Scatter positions are absolute: convert back to room-relative for AddObject.
        const Eigen::Vector3d& pos = placed->position;
        const Eigen::Vector3d c = room.centre();
        // Quads lie on the floor, a few millimetres above it and each at its own height, so
        // neither the floor nor a crossing quad z-fights with them.
        const bool decal = s.type == ObjectType::kQuad;
        o.position =
            Eigen::Vector3d((pos.x() - c.x()) / room.scale.x(), (pos.y() - c.y()) / room.scale.y(),
                            decal ? 0.003 + 0.0002 * (i % 16) : 0.0);
        std::vector<Shape> parts;
        builder->AddObject(o, room, *group_id, &parts);
        // Decals may cross anything (tape over tape); solids keep apart.
        bool ok = !TooClose(parts, path, options.clearance_m);
        for (const auto& g : *groups) {
          if (!ok || decal) break;
          ok = !Overlaps(parts, g, 0.15f);
        }
        if (!ok) continue;
        ++*group_id;
        groups->push_back(std::move(parts));
        break;
      }
    }
  }
}

}  // namespace

Scene BuildScene(const SceneDescription& d, const SceneBuildOptions& options,
                 const std::vector<Eigen::Vector3d>& path, SceneBuildReport* report) {
  options.Check();
  Scene scene;
  scene.name = d.name;
  scene.ambient = static_cast<float>(d.ambient);
  const RoomFrame room = FitRoom(d, options, path);
  SceneBuildReport local_report;
  SceneBuildReport& rep = report ? *report : local_report;
  rep = SceneBuildReport();
  AddMaterials(d, options, options.photo_dir.empty() ? DefaultPhotoDir() : options.photo_dir,
               &scene, &rep);

  Builder builder(d, options);
  Shape room_shape = builder.NewShape(ShapeType::kRoom, "room", 0);
  room_shape.center = (0.5 * (room.min + room.max)).cast<float>();
  room_shape.half = (0.5 * (room.max - room.min)).cast<float>();
  for (int f = 0; f < 6; ++f) room_shape.material[f] = d.MaterialIndex(d.room_materials[f]);
  scene.shapes.push_back(room_shape);

  // Described objects, then scattered ones; a group too close to the path is removed whole.
  std::vector<std::vector<Shape>> groups;
  int group_id = 1;
  for (const ObjectDesc& o : d.objects) {
    std::vector<Shape> parts;
    builder.AddObject(o, room, group_id++, &parts);
    groups.push_back(std::move(parts));
  }
  ScatterObjects(d, options, room, path, &builder, &group_id, &groups);
  rep.objects_placed = static_cast<int>(groups.size());
  for (auto& g : groups) {
    if (TooClose(g, path, options.clearance_m)) {
      ++rep.objects_removed;
      continue;
    }
    for (Shape& s : g) scene.shapes.push_back(std::move(s));
  }
  for (const LightDesc& l : d.lights) {
    Light light;
    light.position = room.Place(l.position).cast<float>();
    light.intensity = static_cast<float>(l.intensity);
    light.range_m = static_cast<float>(l.range_m);
    scene.lights.push_back(light);
  }
  rep.room_min = room.min;
  rep.room_max = room.max;
  return scene;
}

}  // namespace pkslam::sim
