// The scene's reference surface as a dense point cloud (for dense-reconstruction accuracy):
// uniform samples every `spacing_m` on every face, kept where the cameras saw that part of
// the face (SurfaceVisibility cells marked while rendering). Binary little-endian PLY with
// x y z (float), nx ny nz (float), intensity (uchar, the surface albedo).
// The simulator writes two: reference_cloud.ply (every surface cam0 saw at any distance: the
// whole room, for accuracy) and reference_observed.ply (the surfaces cam0 saw within the
// survey range: the denominator of completeness, like a scan of the surveyed area).
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include "sim/renderer.h"
#include "sim/scene.h"

namespace pkslam::sim {

// visibility == nullptr keeps every sample. `description` goes into the PLY header comments.
// Returns the number of points written; throws Error when the file cannot be written.
std::size_t WriteReferenceCloud(const Scene& scene, const SurfaceVisibility* visibility,
                                double spacing_m, const std::filesystem::path& file,
                                const std::string& description = "reference surface");

}  // namespace pkslam::sim
