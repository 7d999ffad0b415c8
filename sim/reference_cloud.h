// The scene's reference surface as a dense point cloud (for dense-reconstruction accuracy):
// uniform samples every `spacing_m` on every face, kept where the cameras saw that part of
// the face (SurfaceVisibility cells marked while rendering). Binary little-endian PLY with
// x y z (float), nx ny nz (float), intensity (uchar, the surface albedo).
#pragma once

#include <cstddef>
#include <filesystem>

#include "sim/renderer.h"
#include "sim/scene.h"

namespace pkslam::sim {

// visibility == nullptr keeps every sample. Returns the number of points written; throws
// Error when the file cannot be written.
std::size_t WriteReferenceCloud(const Scene& scene, const SurfaceVisibility* visibility,
                                double spacing_m, const std::filesystem::path& file);

}  // namespace pkslam::sim
