// The simulated world: a room (inside-out box: floor, walls, ceiling) plus boxes, cylinders
// and quads (markers, posters), each face with a material (texture, physical tile size,
// albedo). Geometry is in float (scenes are < 100 m across; float keeps the renderer fast).
// World frame: z up, gravity along -z (as EuRoC's Vicon/Leica frames).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "sim/texture.h"  // FloorToInt

namespace pkslam::sim {

enum class ShapeType { kRoom, kBox, kCylinder, kQuad };

// Texture layout on a face: tiled every tile_m metres, or stretched once over the face.
struct Material {
  int texture = 0;              // index into Scene::textures
  float tile_m = 1.0f;          // metres per texture repeat (ignored when stretch)
  bool stretch = false;         // map the whole texture once onto the face (markers)
  float albedo = 0.7f;          // reflectance scale
  int macro_texture = -1;       // large-scale albedo variation (-1: none)
  float macro_tile_m = 8.0f;    // metres per macro texture repeat
  float macro_strength = 0.0f;  // albedo *= 1 + strength * (macro - 0.5) * 2
  float emission = 0.0f;        // emitted radiance (windows, lamps), times the texture
  // Each tile shows the texture shifted by a random offset and turned/mirrored by one of
  // the 8 square symmetries (hash of the tile index), so a wall is not a visible grid of
  // identical copies. Off for repetitive textures (the repetition is the point).
  bool shuffle_tiles = true;
};

struct Shape {
  ShapeType type = ShapeType::kBox;
  std::string name;
  int group = -1;  // shapes of one object (shelf) share a group id
  Eigen::Matrix3f world_from_local = Eigen::Matrix3f::Identity();  // columns = local axes
  Eigen::Vector3f center = Eigen::Vector3f::Zero();
  // Room/box: half extents; cylinder: (radius, radius, half height), axis = local z;
  // quad: (half width, half height, 0), normal = local +z, texture up = local +y.
  Eigen::Vector3f half = Eigen::Vector3f::Ones();
  // Per-face material: box/room faces in order -x, +x, -y, +y, -z, +z; cylinder side, bottom,
  // top; quad front (both sides show it).
  std::array<int, 6> material{};
  Eigen::Vector2f uv_offset = Eigen::Vector2f::Zero();  // decorrelates identical materials

  float bound_radius() const;  // bounding sphere about center
  int num_faces() const;
};

struct Light {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  float intensity = 0.5f;  // contribution at distance 0 facing the light
  float range_m = 4.0f;    // falloff 1 / (1 + (d / range)^2)
};

// A ray hit: distance along the (unit) ray, the face and its surface coordinates in metres.
struct Hit {
  float t = 0.0f;
  int shape = -1;
  int face = 0;
  Eigen::Vector2f uv = Eigen::Vector2f::Zero();      // metres on the face
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();  // world, facing the ray origin
};

// Texture coordinates (one unit = one texture) of face point uv (metres) with `material`.
inline Eigen::Vector2f TextureCoords(const Shape& shape, const Material& m,
                                     const Eigen::Vector2f& uv) {
  if (m.stretch) {
    return {uv.x() / (2.0f * shape.half.x()), 1.0f - uv.y() / (2.0f * shape.half.y())};
  }
  const float inv_tile = 1.0f / m.tile_m;
  float s = (uv.x() + shape.uv_offset.x()) * inv_tile;
  float t = -(uv.y() + shape.uv_offset.y()) * inv_tile;
  if (!m.shuffle_tiles) return {s, t};
  const float fs = static_cast<float>(FloorToInt(s));
  const float ft = static_cast<float>(FloorToInt(t));
  float ls = s - fs;
  float lt = t - ft;
  std::uint32_t h = static_cast<std::uint32_t>(static_cast<std::int32_t>(fs)) * 0x9E3779B1u ^
                    static_cast<std::uint32_t>(static_cast<std::int32_t>(ft)) * 0x85EBCA77u;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  if (h & 1u) std::swap(ls, lt);
  if (h & 2u) ls = 1.0f - ls;
  if (h & 4u) lt = 1.0f - lt;
  return {ls + static_cast<float>((h >> 8) & 0xFFFu) * (1.0f / 4096.0f),
          lt + static_cast<float>((h >> 20) & 0xFFFu) * (1.0f / 4096.0f)};
}

// Ray/shape tests in a shape's local frame: IntersectLocal in sim/intersect.h (inline).

// Signed distance from a world point to the shape's surface (negative inside solids; for the
// room, distance to the nearest wall, negative outside the room).
float SignedDistance(const Shape& shape, const Eigen::Vector3f& p_world);

struct Scene {
  std::string name;
  std::vector<Shape> shapes;
  std::vector<Material> materials;
  std::vector<MipTexture> textures;
  std::vector<Light> lights;
  float ambient = 0.6f;

  // Nearest hit over all shapes (reference implementation: tests, point cloud, motion
  // planning). The renderer uses its own culled loop with identical per-shape tests.
  bool Intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_max,
                 Hit* hit) const;
  // Distance from p to the nearest non-room surface (infinity when there are none) and to
  // the room's walls.
  float ObjectClearance(const Eigen::Vector3f& p) const;
  float RoomClearance(const Eigen::Vector3f& p) const;
  // The room shape, or nullptr.
  const Shape* Room() const;
  // Local (u, v) axes of a face in the shape's frame and its extent in metres, for
  // sampling surfaces: point = center + R * (origin + u * axis_u + v * axis_v).
  struct FaceFrame {
    Eigen::Vector3f origin;
    Eigen::Vector3f axis_u;
    Eigen::Vector3f axis_v;
    Eigen::Vector3f normal;  // local, pointing out of the surface into free space
    Eigen::Vector2f size;    // metres along u, v (cylinder side: circumference, height)
  };
  static FaceFrame Face(const Shape& shape, int face);
  // The world point and outward normal at face coordinates uv (metres, within Face().size);
  // false for a cylinder cap sample outside its disc.
  static bool SurfacePoint(const Shape& shape, int face, const Eigen::Vector2f& uv,
                           Eigen::Vector3f* p_world, Eigen::Vector3f* n_world);
};

}  // namespace pkslam::sim
