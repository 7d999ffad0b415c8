// Point clouds and their PLY files: the project's PLY module (`pkslam dense` and `pkslam tracks`
// write it, `pkslam cloud-compare` reads it). A PointCloud is a plain value type.
//
// Reading: PLY "ascii 1.0" or "binary_little_endian 1.0"; the vertex element must come first
// (elements after it, e.g. faces, are ignored). x, y, z are required (any numeric type);
// colour comes from red/green/blue (or r/g/b), grey from intensity/grey/gray (replicated to
// r = g = b); a "views" property is kept, and nx, ny, nz normals (the simulator's reference).
// Errors throw InputError naming the file and the header line (or the vertex) at fault. Writing:
// binary little-endian, x y z float, then nx ny nz float when the cloud has normals, then
// optionally one uchar "intensity" (grey) or uchar red green blue (colour), then optionally
// uchar "views". Every PLY point file of the project goes through here (map points, dense
// clouds, the RGB-D voxel map, the simulator's reference clouds, the tracks map); meshes are
// Open3D's (dense/mesh.h).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace pkslam {

using Rgb = std::array<std::uint8_t, 3>;

struct PointCloud {
  std::vector<Eigen::Vector3f> points;
  std::vector<Rgb> colours;              // empty or one per point (grey: r = g = b)
  std::vector<std::uint8_t> views;       // empty or one per point: keyframes that saw it (capped)
  std::vector<Eigen::Vector3f> normals;  // empty or one unit normal per point

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool has_colour() const { return !colours.empty(); }
  bool has_views() const { return !views.empty(); }
  bool has_normals() const { return !normals.empty(); }
  // Throws Error when the optional arrays do not have one entry per point.
  void CheckSizes() const;
};

enum class PlyColour {
  kNone,  // positions only
  kGrey,  // one uchar "intensity" per point (mean of r, g, b)
  kRgb,   // uchar red, green, blue
};

// Reads a PLY point cloud (see above).
PointCloud ReadPly(const std::filesystem::path& file);

// Writes a binary little-endian PLY. kGrey/kRgb need colours. `comment` (single line) goes
// into the header. Throws Error when the file cannot be written.
void WritePly(const PointCloud& cloud, const std::filesystem::path& file, PlyColour colour,
              const std::string& comment = "");
// The same with several header comment lines.
void WritePly(const PointCloud& cloud, const std::filesystem::path& file, PlyColour colour,
              const std::vector<std::string>& comments);

}  // namespace pkslam
