// Meshes from the keyframes (`pkslam dense --mesh`): each keyframe's depth map is fused at the
// run's keyframe pose into Open3D's ScalableTSDFVolume (a hashed, sparse truncated signed
// distance volume, Curless & Levoy averaging), and its zero level set is extracted with
// Open3D's marching cubes as a triangle mesh written as binary PLY (Open3D's writer). The depth
// maps are those the point cloud keeps after its multi-view filter (BuildFilteredTsdfMesh, the
// default: on a 40 s V1_02 replay 1.44 cm mean accuracy against the cloud's 1.93) or each
// keyframe's raw SGBM / RGB-D depth (BuildTsdfMesh: 2.20 cm).
// cloud-compare measures a mesh through points sampled uniformly on its triangles.
//
// Depth maps are computed in parallel batches (TBB) and integrated in keyframe order: the mesh
// does not depend on the thread count.
#pragma once

#include <cstddef>
#include <filesystem>

#include "dense/dense_cloud.h"
#include "io/point_cloud.h"
#include "io/trajectory.h"

namespace pkslam::dense {

struct MeshOptions {
  // 2 cm: at 1 cm each voxel averages fewer depth samples and the 40 s V1_02 mesh was less
  // accurate (2.70 vs 2.20 cm mean) with 4.3x the memory (docs/dense.md).
  double voxel_m = 0.02;       // TSDF voxel side
  double truncation_m = 0.06;  // signed distance truncation (three voxels)
  // Depth maps as `pkslam dense` computes them (range, border, stereo settings, batch size).
  DenseOptions depth;
  // Fuse the depth after the point cloud's multi-view filter (BuildFilteredTsdfMesh) rather
  // than each keyframe's raw depth map.
  bool filtered_depth = true;
  void Check() const;
};

struct MeshStats {
  int keyframes = 0;
  int keyframes_used = 0;
  std::size_t vertices = 0;
  std::size_t triangles = 0;
  double seconds = 0;
  double peak_memory_mib = 0;  // of the process after the fusion
};

// Fuses the keyframes and writes the mesh to `file`. Throws InputError when no keyframe
// matches a dataset frame, Error when the mesh is empty or cannot be written.
MeshStats BuildTsdfMesh(const Trajectory& keyframes, const KeyframeImageSource& source,
                        const MeshOptions& options, const std::filesystem::path& file);

// The same fusion fed with the depth maps after the point cloud's multi-view filter
// (dense/dense_cloud.h): one pass builds the cloud (*cloud, *cloud_stats) and the mesh.
MeshStats BuildFilteredTsdfMesh(const Trajectory& keyframes, const KeyframeImageSource& source,
                                const MeshOptions& options, const std::filesystem::path& file,
                                PointCloud* cloud, DenseStats* cloud_stats);

// Whether a PLY file has a face element with at least one face.
bool PlyHasFaces(const std::filesystem::path& file);

// Points sampled uniformly by area on a PLY mesh, about one per spacing_m^2 (Open3D). Throws
// InputError when the file is not a readable mesh.
PointCloud SampleMesh(const std::filesystem::path& file, double spacing_m);

}  // namespace pkslam::dense
