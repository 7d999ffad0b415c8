// Ray-casting renderer. Per-pixel bearing vectors come from CameraModel::Unproject (so lens
// distortion is exact); shapes are culled per 16x16 tile against the tile's cone of rays, by
// their bounding sphere and then by spheres around their parts (SegmentSpheres), which also
// bound how near a hit can be, so a ray skips shapes it cannot reach before its current hit;
// shading = albedo (mip-mapped texture, footprint from distance, incidence and the pixel's
// angular size) x (ambient + soft point lights). Output is linear radiance (sensor effects
// are in sensor_model.h) and optionally depth along the optical axis.
//
// Threads: Render() parallelises over tiles with TBB; the Renderer, Scene and CameraRays are
// read-only during a call, so one Renderer may serve several threads.
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "core/camera/camera_model.h"
#include "core/geometry/se3.h"
#include "sim/scene.h"

namespace pkslam::sim {

// Precomputed per-camera ray geometry (built once per camera model).
class CameraRays {
 public:
  // supersample: s x s rays per pixel (s >= 1) on a regular sub-pixel grid.
  CameraRays(const CameraModel& camera, int supersample = 1);

  int width() const { return width_; }
  int height() const { return height_; }
  int supersample() const { return supersample_; }
  // Unit bearing (camera frame) of sub-sample k of pixel (x, y).
  const Eigen::Vector3f& Ray(int x, int y, int k = 0) const {
    return rays_[(static_cast<std::size_t>(y) * width_ + x) * samples_ + k];
  }
  // Angular size (rad) of a pixel at (x, y) (geometric mean of its two sides).
  float PixelAngle(int x, int y) const { return pixel_angle_[y * width_ + x]; }

  struct Tile {
    int x0, y0, x1, y1;        // pixel range [x0, x1) x [y0, y1)
    Eigen::Vector3f axis;      // unit, camera frame
    float cos_half, sin_half;  // cone half-angle containing every ray of the tile
  };
  const std::vector<Tile>& tiles() const { return tiles_; }
  static constexpr int kTileSize = 16;

 private:
  int width_ = 0;
  int height_ = 0;
  int supersample_ = 1;
  int samples_ = 1;
  std::vector<Eigen::Vector3f> rays_;
  std::vector<float> pixel_angle_;
  std::vector<Tile> tiles_;
};

// Marks which parts of which faces were seen (for the reference point clouds): per face a
// grid of cells; set bits are seen. With max_depth_m > 0 only hits at a depth (along the
// optical axis) of at most max_depth_m mark a cell: the surfaces a camera observed within a
// survey range. Thread-safe marking (atomic OR, so the result does not depend on the order);
// see reference_cloud.h.
class SurfaceVisibility {
 public:
  SurfaceVisibility(const Scene& scene, float cell_m, float max_depth_m = 0.0f);
  // depth_m: of the hit along the camera's optical axis.
  void Mark(int shape, int face, const Eigen::Vector2f& uv, float depth_m);
  bool Seen(int shape, int face, const Eigen::Vector2f& uv) const;
  float cell_m() const { return cell_m_; }
  float max_depth_m() const { return max_depth_m_; }

 private:
  struct FaceGrid {
    int cols = 0;
    int rows = 0;
    std::size_t first_word = 0;
  };
  bool Index(int shape, int face, const Eigen::Vector2f& uv, std::size_t* word,
             std::uint64_t* bit) const;

  float cell_m_ = 0.05f;
  float max_depth_m_ = 0.0f;                  // 0: any depth
  std::vector<std::vector<FaceGrid>> faces_;  // [shape][face]
  std::vector<std::atomic<std::uint64_t>> bits_;
};

struct RenderOptions {
  float lod_bias = 0.0f;        // added to the mip level (> 0 blurs, < 0 sharpens/aliases)
  bool colour = false;          // render RGB radiance (CV_32FC3) instead of grey (CV_32FC1)
  bool depth = false;           // also output depth along the optical axis (CV_32F, 0 = none)
  float max_distance = 200.0f;  // metres

  void Check() const;
};

struct RenderBuffers {
  cv::Mat radiance;  // CV_32FC1 (grey) or CV_32FC3 (RGB), linear, ~[0, 1]
  cv::Mat depth;     // CV_32F metres along the camera z axis (only with options.depth)
};

// A sphere bounding part of a shape (centre in the shape's frame). Long and flat shapes get a
// row or grid of them, so tile culling and the nearest-possible-hit bound follow the shape
// rather than one sphere around all of it (a pipe, a rail, a floor mat).
struct BoundSphere {
  Eigen::Vector3f centre_local = Eigen::Vector3f::Zero();
  float radius = 0.0f;
};
// Spheres whose union contains every point of `shape` (none for the room, which is never
// culled): at most 16.
std::vector<BoundSphere> SegmentSpheres(const Shape& shape);

class Renderer {
 public:
  // Keeps a reference to `scene` and its shapes' part spheres: the scene must outlive the
  // Renderer and keep its shapes (Render checks their count).
  Renderer(const Scene& scene, const RenderOptions& options);

  // Renders the view of a camera at world_from_camera (optical frame: z forward, y down).
  // Every ray's hit marks each of `visibility` (null entries are skipped).
  void Render(const CameraRays& rays, const SE3d& world_from_camera, RenderBuffers* out,
              std::span<SurfaceVisibility* const> visibility = {}) const;

  const RenderOptions& options() const { return options_; }

 private:
  const Scene& scene_;
  RenderOptions options_;
  // SegmentSpheres of each shape split into parts (empty where one sphere fits it).
  std::vector<std::vector<BoundSphere>> bounds_;
};

}  // namespace pkslam::sim
